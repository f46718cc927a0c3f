// One interface for every point-vs-surface method (exact BVH, sphere tree, knee groups), so the
// CLI, the world and the benchmarks can switch methods by name.
#pragma once

#include "hapsim/collision/surface_point.h"

#include <cstddef>
#include <string_view>

namespace hapsim {

class ProximityQuery {
 public:
  ProximityQuery() = default;
  ProximityQuery(const ProximityQuery&) = delete;
  ProximityQuery& operator=(const ProximityQuery&) = delete;
  virtual ~ProximityQuery() = default;

  /// Exact closest surface point to `p` (mesh frame). `hint`, if given, is read as last cycle's
  /// answer and updated with this one. haptic path: no allocation.
  [[nodiscard]] virtual SurfacePoint closest_point(const Vec3& p,
                                                   QueryHint* hint = nullptr) const = 0;

  /// "Is the surface within `radius` of `p`, and where?" Exits early, without exploring the
  /// rest of the mesh, once nothing can be within `radius`. Returns true and fills `out` with the
  /// exact closest point when its unsigned distance is <= radius; false otherwise (the probe is
  /// clear of the surface, or deeper inside than `radius`). haptic path: no allocation.
  virtual bool contact_within(const Vec3& p, double radius, SurfacePoint* out,
                              QueryHint* hint = nullptr) const = 0;

  /// Call after the mesh's vertices moved (same triangles): bounds are refitted, not rebuilt.
  virtual void refit() = 0;

  /// Bytes of the acceleration structure, sign data included, mesh excluded.
  [[nodiscard]] virtual std::size_t memory_bytes() const = 0;
  [[nodiscard]] virtual std::string_view method_name() const = 0;
};

}  // namespace hapsim
