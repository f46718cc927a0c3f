// The proxy / god-object method (Zilles & Salisbury 1995; Ruspini et al. 1997): a proxy sphere
// follows the device but never enters a surface, so a fast probe cannot pop through a thin sheet
// or ligament; the force is a spring from the device to the proxy.
//
// Motion: each cycle the proxy moves towards the device position in steps no longer than its
// clearance (sphere tracing: nothing can be crossed) or, in contact, than `max_substep_m` (less
// than half the thinnest closed feature), after which any penetration is resolved along the
// surface normal. Remaining motion is projected onto the active contact planes (sliding).
// Open surfaces (a sheet) are two-sided: the proxy remembers which side it is on.
// Coulomb friction keeps the proxy stuck while the device stays inside the friction cone.
#pragma once

#include "hapsim/collision/proximity_query.h"
#include "hapsim/core/types.h"
#include "hapsim/force/contact_material.h"

#include <array>
#include <cstdint>
#include <optional>
#include <span>

namespace hapsim {

/// One surface the proxy must stay outside of (owned by the world; the proxy only reads it).
struct ProxySurface {
  const ProximityQuery* query = nullptr;  // answers in the body frame
  Iso3 X_world_body = Iso3::Identity();   // where the body is
  const ContactMaterial* material = nullptr;
  bool two_sided = false;     // open mesh: both sides are outside
  QueryHint* hint = nullptr;  // temporal coherence, one per tool-surface pair
};

struct ProxyContact {
  int surface = -1;                  // index into the span given to update()
  Vec3 point_world = Vec3::Zero();   // closest surface point
  Vec3 normal_world = Vec3::Zero();  // unit, pointing from the surface to the proxy
  std::uint32_t triangle = kNoTriangle;
  double clearance_m = 0.0;  // proxy-to-surface gap (< 0 while penetrating)
};

struct GodObjectParams {
  double radius_m = 0.0;              // tool sphere radius (0: a point probe)
  double contact_tolerance_m = 1e-5;  // within this of a surface counts as touching
  double max_substep_m = 2.5e-4;      // step length while in contact
  int max_iterations = 16;            // work bound per cycle (motion carries over)
  /// Farthest a probe looks (and so the longest free-space stride): a proxy left far behind
  /// (the device pushed through a body) would otherwise probe every surface out to that
  /// distance. It still travels up to max_iterations strides a cycle.
  double max_probe_margin_m = 0.01;
};

class GodObject {
 public:
  static constexpr int kMaxSurfaces = 64;
  static constexpr int kMaxContacts = 4;

  explicit GodObject(GodObjectParams params = {});

  /// Places the proxy (e.g. at the device's first position, which must be outside surfaces).
  void reset(const Vec3& p_world);

  /// Moves the proxy towards `device_p_world`. haptic path: no allocation.
  void update(const Vec3& device_p_world, std::span<const ProxySurface> surfaces);

  [[nodiscard]] const Vec3& proxy_world() const { return proxy_world_; }
  [[nodiscard]] std::span<const ProxyContact> contacts() const {
    return {contacts_.data(), static_cast<std::size_t>(contact_count_)};
  }
  [[nodiscard]] bool in_contact() const { return contact_count_ > 0; }
  /// Iterations the last update used (bounded by params.max_iterations).
  [[nodiscard]] int iterations_used() const { return iterations_used_; }
  [[nodiscard]] const GodObjectParams& params() const { return params_; }

 private:
  struct Probe {
    double clearance_m;  // distance from the proxy sphere to the surface (< 0: penetrating)
    Vec3 normal_world;   // from the surface towards the proxy side
    Vec3 point_world;
    std::uint32_t triangle;
  };
  /// Clearance of the proxy sphere at `p_world` to one surface, looking no farther than
  /// `margin_m` (beyond it the query exits early and the clearance is reported as margin_m).
  Probe probe(const ProxySurface& surface, int index, const Vec3& p_world, double margin_m);
  /// Fills contacts_ (clearance < tolerance) at the current proxy; returns the least clearance.
  double scan(std::span<const ProxySurface> surfaces, double margin_m);
  /// Pushes the proxy out of any surface it penetrates, along that surface's normal.
  double resolve_penetration(std::span<const ProxySurface> surfaces, double margin_m);
  /// The first contact's friction seen from the proxy's position before this update moved it
  /// along the surface: its normal, the device's offset in the tangent plane, and the static and
  /// dynamic cones' radii at the device's depth. None without a contact, friction or depth.
  struct FrictionCone {
    Vec3 normal_world;
    Vec3 tangential_world;
    double tangential_m;
    double static_radius_m;
    double dynamic_radius_m;
  };
  [[nodiscard]] std::optional<FrictionCone> friction_cone(
      const Vec3& previous_proxy_world, const Vec3& device_p_world,
      std::span<const ProxySurface> surfaces) const;
  /// Whether the device is inside the static friction cone of the first contact, seen from the
  /// proxy's position before this update moved it along the surface.
  [[nodiscard]] bool sticks(const Vec3& previous_proxy_world, const Vec3& device_p_world,
                            std::span<const ProxySurface> surfaces) const;
  /// How far along the surface the proxy may slide this cycle: as far as the dynamic friction
  /// cone of the first contact leaves it behind the device (unbounded without friction).
  [[nodiscard]] double slide_budget(const Vec3& previous_proxy_world, const Vec3& device_p_world,
                                    std::span<const ProxySurface> surfaces) const;
  void apply_friction(const Vec3& previous_proxy_world, const Vec3& device_p_world,
                      std::span<const ProxySurface> surfaces, double margin_m);
  /// A proxy left out of contact just off a surface the device is beyond (a friction step in a
  /// convex surface's tangent plane, or the iterations spent between leaving one surface and
  /// meeting the next) is moved back onto it along its normal: otherwise that cycle renders no
  /// force with the device inside the body.
  void settle_onto_nearest(const Vec3& device_p_world, std::span<const ProxySurface> surfaces,
                           double margin_m);

  GodObjectParams params_;
  Vec3 proxy_world_ = Vec3::Zero();
  std::array<ProxyContact, kMaxContacts> contacts_{};
  int contact_count_ = 0;
  /// The nearest surface at the last scan (also when farther than the contact tolerance).
  double nearest_clearance_m_ = 0.0;
  Vec3 nearest_normal_world_ = Vec3::Zero();
  int nearest_surface_ = -1;
  int iterations_used_ = 0;
  /// Side of each two-sided surface the proxy is on (+1 front, −1 back, 0 unknown yet).
  std::array<std::int8_t, kMaxSurfaces> side_{};
  /// Broad phase of one update(): surfaces with something within reach of this update's motion.
  std::array<std::uint8_t, kMaxSurfaces> nearby_{};
  bool cull_ = false;
};

/// Spring force from the device to the proxy with the touched material's stiffness, maximum
/// penetration and maximum force, and normal damping from the device velocity. Zero when not in
/// contact. haptic path.
Vec3 proxy_force(const GodObject& proxy, std::span<const ProxySurface> surfaces,
                 const Vec3& device_p_world, const Vec3& device_v_world);

}  // namespace hapsim
