// Typed indices of a world (architecture.md, Notation, "Indices"): a body, a tool, and the two
// numberings of a segment — the FLAT index over all bodies' segments (WorldModel::segments(),
// WorldState::segments, PenaltyCandidate) and the BODY-LOCAL index within its body
// (WorldContact, BodyContact, what users read). Each is one integer of the size the field had
// before it was typed (records on the haptic path and in lock-free buffers keep their layout), is
// built from an integer only explicitly, and converts to no other index: a FlatSegment cannot be
// passed where a LocalSegment is meant. `flat_segment(body, local)` (WorldModel, World) is the
// one way from a body-local index to the flat one.
#pragma once

#include <compare>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <type_traits>

namespace hapsim {

/// An integer index of one kind (Tag). Signed kinds use −1 as "none" (valid() is false).
template <class Tag, std::integral Rep>
struct StrongIndex {
  using rep = Rep;
  Rep value{};

  constexpr StrongIndex() noexcept = default;
  /// From any integer (a loop counter, a container size): explicit only.
  template <std::integral I>
  requires(!std::same_as<I, bool>) constexpr explicit StrongIndex(I v) noexcept
      : value(static_cast<Rep>(v)) {}

  /// Whether it names something (not the −1 of a signed kind).
  [[nodiscard]] constexpr bool valid() const noexcept {
    if constexpr (std::is_signed_v<Rep>) {
      return value >= 0;
    } else {
      return true;
    }
  }
  /// For indexing a container (only on a valid index).
  [[nodiscard]] constexpr std::size_t index() const noexcept {
    return static_cast<std::size_t>(value);
  }

  /// Prints the integer (diagnostics, test failures); any stream that prints a Rep.
  template <class Stream>
  requires requires(Stream& os, Rep v) { os << v; }
  friend Stream& operator<<(Stream& os, StrongIndex i) {
    os << i.value;
    return os;
  }

  friend constexpr bool operator==(StrongIndex, StrongIndex) noexcept = default;
  friend constexpr auto operator<=>(StrongIndex, StrongIndex) noexcept = default;
};

struct BodyIndexTag;
struct ToolIndexTag;
struct FlatSegmentTag;
struct LocalSegmentTag;

/// A body's place in WorldDescription::bodies.
using BodyIndex = StrongIndex<BodyIndexTag, std::int32_t>;
/// A tool's place in WorldDescription::tools (all users together).
using ToolIndex = StrongIndex<ToolIndexTag, std::int32_t>;
/// A segment's place in the flat list of every body's segments (WorldModel::segments()).
using FlatSegment = StrongIndex<FlatSegmentTag, std::uint32_t>;
/// A segment's place in its body's segments (SegmentModel::index_in_body).
using LocalSegment = StrongIndex<LocalSegmentTag, std::int32_t>;

/// "None" of each signed kind (a default WorldContact or BodyContact).
inline constexpr BodyIndex kNoBody{-1};
inline constexpr ToolIndex kNoTool{-1};
inline constexpr LocalSegment kNoSegment{-1};

static_assert(sizeof(BodyIndex) == sizeof(std::int32_t) &&
              sizeof(ToolIndex) == sizeof(std::int32_t));
static_assert(sizeof(FlatSegment) == sizeof(std::uint32_t));
static_assert(sizeof(LocalSegment) == sizeof(std::int32_t));
static_assert(std::is_trivially_copyable_v<BodyIndex> && std::is_trivially_copyable_v<ToolIndex> &&
              std::is_trivially_copyable_v<FlatSegment> &&
              std::is_trivially_copyable_v<LocalSegment>);
static_assert(!std::is_convertible_v<FlatSegment, LocalSegment> &&
              !std::is_convertible_v<LocalSegment, FlatSegment>);
static_assert(!std::is_constructible_v<LocalSegment, FlatSegment> &&
              !std::is_constructible_v<FlatSegment, LocalSegment>);
static_assert(!std::is_convertible_v<int, LocalSegment> &&
              !std::is_convertible_v<LocalSegment, int>);

}  // namespace hapsim
