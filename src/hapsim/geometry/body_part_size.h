// Is a loaded mesh the size of a body part? A mesh file carries no unit: a scene's "scale" says
// how many metres one file unit is, and the usual mistake is the wrong one (a knee in millimetres
// read as metres is a 42 m patella; one in metres read as millimetres a 0.04 mm bone). Nothing
// can be refused for that — a scene may well model something odd — but the loader says so and
// names the scale that would fix it (scene/geometry_reader.cpp, docs/scene-format.md "Warnings").
#pragma once

#include <optional>
#include <string>

namespace hapsim {

/// The plausible largest extent (longest side of the axis-aligned bounds) of what a scene's
/// meshes model, metres: body parts, from the smallest a fingertip can palpate as a part of its
/// own (a small tendon slip, a few millimetres; below 1 mm is finer than the haptic contact
/// itself resolves) up to a whole adult body (about 2 m) with margin. A unit mistake is a
/// factor of 10 to 1000 and lands well outside.
inline constexpr double kBodyPartMinExtentM = 1e-3;
inline constexpr double kBodyPartMaxExtentM = 3.0;

/// What is implausible about a mesh's size and the scale that would fix it.
struct MeshScaleAdvice {
  /// The mesh's largest extent at `scale`, metres.
  double extent_m = 0.0;
  /// The scale it was loaded at, metres per file unit.
  double scale = 1.0;
  /// Above kBodyPartMaxExtentM (else below kBodyPartMinExtentM).
  bool too_large = false;
  /// A scale that puts the extent within range: a common unit (0.001 mm, 0.01 cm, 1 m) where one
  /// does, tried in the order of the likely mistakes (too large: millimetres, then centimetres;
  /// too small: metres, then centimetres); else the power-of-ten multiple of `scale` that brings
  /// the extent nearest 10 cm.
  double suggested_scale = 1.0;
  /// "millimetres read as metres" when both scales are common units, else empty.
  std::string likely_mistake;
};

/// The plausibility rule: nullopt when `extent_m` (a mesh's largest extent loaded at `scale`
/// metres per file unit) is within [kBodyPartMinExtentM, kBodyPartMaxExtentM], or when either
/// number is not finite and positive (degenerate meshes are reported by validation instead).
[[nodiscard]] std::optional<MeshScaleAdvice> check_body_part_size(double extent_m, double scale);

/// "is 42 m across at scale 1: implausibly large for a body part (1 mm to 3 m); millimetres
/// read as metres? Use "scale": 0.001" — the advice as the tail of a message naming the mesh.
[[nodiscard]] std::string describe(const MeshScaleAdvice& advice);

/// A length for messages: "42 m", "470 mm", "0.04 mm" (4 significant digits).
[[nodiscard]] std::string format_length(double metres);
/// A scale for messages, as it would be written in a scene: "0.001", "1", "1e-06".
[[nodiscard]] std::string format_scale(double scale);

}  // namespace hapsim
