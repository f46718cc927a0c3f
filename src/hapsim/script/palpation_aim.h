// Aiming a scripted press at a world: where a palpation target lands, found by sphere tracing the
// exact rest surfaces from far out along the target's `from` direction, so the first surface met
// counts (skin over bone, as a finger would). The scene file names the target
// (scene/device_reader.h); the palpation plans (script/scene_palpation_plan.h,
// script/glove_palpation_plan.h) aim with it.
#pragma once

#include "hapsim/core/types.h"

#include <cstddef>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace hapsim {

class MeshBvh;
class World;

/// One press of a scripted palpation: the probe comes at the named segment from direction
/// `from_world` (a unit vector pointing from the segment towards where the probe starts), touches
/// the first surface on that line (skin, if the segment is under it) and presses `depth_m` past it.
struct PalpationTargetDescription {
  std::string body;     // body name
  std::string segment;  // segment name within the body
  /// Aim at this point (world frame) instead of the segment's centroid: a landmark inside a body
  /// that is no segment of it (the MCL inside a FEM knee's tissue). The surface met is still the
  /// body's first, coming from `from_world`.
  std::optional<Vec3> toward_world;
  Vec3 from_world = Vec3::UnitY();
  double depth_m = 0.006;
  double hold_s = 0.5;
};

/// Where a palpation target lands: the first surface of `body` (any of its segments) met on the
/// line from far out along `from_world` towards the named segment's centroid, by sphere tracing
/// on the exact rest surfaces. Throws hapsim::Error naming the body/segment if nothing is hit.
struct PalpationAim {
  Vec3 surface_world = Vec3::Zero();
  std::size_t hit_segment = 0;  // segment of the body whose surface was met first
};

/// The world's body named `name` (the only body when `name` is empty and there is one). Throws
/// hapsim::Error ("palpation target") when there is none.
[[nodiscard]] std::size_t find_body(const World& world, const std::string& name);

/// The segment named `name` of body `body`. Throws hapsim::Error ("palpation target") naming both
/// when there is none.
[[nodiscard]] std::size_t find_segment(const World& world, std::size_t body,
                                       const std::string& name);

/// Exact rest-surface queries of a body's segments, built once per body: aiming must not depend on
/// the world's (possibly approximate, near-surface-only) contact method.
class ExactBodies {
 public:
  explicit ExactBodies(const World& world);
  ~ExactBodies();
  ExactBodies(const ExactBodies&) = delete;
  ExactBodies& operator=(const ExactBodies&) = delete;
  const std::vector<std::unique_ptr<MeshBvh>>& body(std::size_t b);

 private:
  const World& world_;
  std::map<std::size_t, std::vector<std::unique_ptr<MeshBvh>>> cache_;
};

[[nodiscard]] PalpationAim aim_palpation_target(const World& world,
                                                const PalpationTargetDescription& target);

/// The same, with the exact surfaces of earlier aims at the same world kept in `exact`.
[[nodiscard]] PalpationAim aim_palpation_target(const World& world,
                                                const PalpationTargetDescription& target,
                                                ExactBodies& exact);

}  // namespace hapsim
