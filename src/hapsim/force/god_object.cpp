#include "hapsim/force/god_object.h"

#include "hapsim/force/penalty_force.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hapsim {

GodObject::GodObject(GodObjectParams params) : params_(params) {}

void GodObject::reset(const Vec3& p_world) {
  proxy_world_ = p_world;
  contact_count_ = 0;
  iterations_used_ = 0;
  side_.fill(0);
}

// haptic path
GodObject::Probe GodObject::probe(const ProxySurface& surface, int index, const Vec3& p_world,
                                  double margin_m) {
  Probe out{margin_m, Vec3::Zero(), Vec3::Zero(), kNoTriangle};
  if (surface.query == nullptr) {
    return out;
  }
  const Vec3 p_body = surface.X_world_body.inverse() * p_world;
  SurfacePoint sp;
  if (!surface.query->contact_within(p_body, params_.radius_m + margin_m, &sp, surface.hint)) {
    return out;  // nothing within the margin: the clearance is at least margin_m
  }
  const Mat3 R = surface.X_world_body.linear();
  double distance = sp.signed_distance;
  Vec3 normal_body = sp.normal;
  if (surface.two_sided && index < kMaxSurfaces) {
    std::int8_t& side = side_[static_cast<std::size_t>(index)];
    // The side is learnt only while clearly away from the surface, so it never flips by a
    // crossing; going round an open edge at a distance updates it.
    if (side == 0 || std::abs(distance) > params_.radius_m + 2.0 * params_.max_substep_m) {
      side = distance >= 0.0 ? 1 : -1;
    }
    distance *= side;
    normal_body *= side;
  }
  out.clearance_m = distance - params_.radius_m;
  out.normal_world = R * normal_body;
  out.point_world = surface.X_world_body * sp.point;
  out.triangle = sp.triangle;
  return out;
}

// haptic path
double GodObject::scan(std::span<const ProxySurface> surfaces, double margin_m) {
  contact_count_ = 0;
  nearest_clearance_m_ = margin_m;
  nearest_normal_world_ = Vec3::Zero();
  nearest_surface_ = -1;
  double least = margin_m;
  const int n = static_cast<int>(std::min<std::size_t>(surfaces.size(), kMaxSurfaces));
  for (int i = 0; i < n; ++i) {
    if (cull_ && nearby_[static_cast<std::size_t>(i)] == 0) {
      continue;  // out of this update's reach (see update()): clearance >= margin_m
    }
    const Probe pr = probe(surfaces[static_cast<std::size_t>(i)], i, proxy_world_, margin_m);
    if (pr.clearance_m < nearest_clearance_m_) {
      nearest_clearance_m_ = pr.clearance_m;
      nearest_normal_world_ = pr.normal_world;
      nearest_surface_ = i;
    }
    least = std::min(least, pr.clearance_m);
    if (!(pr.clearance_m < params_.contact_tolerance_m)) {
      continue;
    }
    const ProxyContact c{i, pr.point_world, pr.normal_world, pr.triangle, pr.clearance_m};
    if (contact_count_ < kMaxContacts) {
      contacts_[static_cast<std::size_t>(contact_count_++)] = c;
    } else {  // keep the deepest ones
      auto worst = std::max_element(contacts_.begin(), contacts_.end(),
                                    [](const ProxyContact& a, const ProxyContact& b) {
                                      return a.clearance_m < b.clearance_m;
                                    });
      if (c.clearance_m < worst->clearance_m) {
        *worst = c;
      }
    }
  }
  return least;
}

// haptic path
double GodObject::resolve_penetration(std::span<const ProxySurface> surfaces, double margin_m) {
  double least = margin_m;
  for (int pass = 0; pass < 4; ++pass) {
    least = scan(surfaces, margin_m);
    bool pushed = false;
    for (int k = 0; k < contact_count_; ++k) {
      const ProxyContact& c = contacts_[static_cast<std::size_t>(k)];
      if (c.clearance_m < 0.0) {
        proxy_world_ += c.normal_world * (-c.clearance_m);
        pushed = true;
      }
    }
    if (!pushed) {
      break;
    }
  }
  return least;
}

namespace {

// Removes from `motion` every component that would push into an active contact plane.
// Gauss-Seidel projection; three passes settle two planes, three planes block all motion.
Vec3 project_onto_contacts(Vec3 motion, std::span<const ProxyContact> contacts) {
  for (int pass = 0; pass < 3; ++pass) {
    bool changed = false;
    for (const ProxyContact& c : contacts) {
      const double into = motion.dot(c.normal_world);
      if (into < 0.0) {
        motion -= into * c.normal_world;
        changed = true;
      }
    }
    if (!changed) {
      return motion;
    }
  }
  for (const ProxyContact& c : contacts) {
    if (motion.dot(c.normal_world) < -1e-12) {
      return Vec3::Zero();  // wedged in a corner
    }
  }
  return motion;
}

}  // namespace

// haptic path
void GodObject::update(const Vec3& device_p_world, std::span<const ProxySurface> surfaces) {
  if (!device_p_world.allFinite()) {
    return;  // never follow a NaN: hold the proxy where it is
  }
  const Vec3 previous = proxy_world_;
  // Look only as far as this cycle's motion can reach (queries exit early beyond it), and never
  // farther than max_probe_margin_m.
  const double gap = (device_p_world - proxy_world_).norm();
  const double margin = std::min(std::max(gap, params_.max_substep_m),
                                 std::max(params_.max_probe_margin_m, params_.max_substep_m)) +
                        params_.contact_tolerance_m;
  // Broad phase: every step of the loop below moves the proxy along a projection of (device -
  // proxy), which never brings it farther from the device, so it stays within 2·gap of where it
  // starts; and each of at most max_iterations steps is at most `margin` long (push-outs are
  // within the tolerance). A surface that matters must come within `margin` of one of those
  // positions: one with nothing that close to the reachable ball now is not probed again.
  const double travel = std::min(2.0 * gap, params_.max_iterations * margin);
  const double reach = travel + margin + params_.contact_tolerance_m;
  const int n = static_cast<int>(std::min<std::size_t>(surfaces.size(), kMaxSurfaces));
  for (int i = 0; i < n; ++i) {
    const Probe pr = probe(surfaces[static_cast<std::size_t>(i)], i, proxy_world_, reach);
    nearby_[static_cast<std::size_t>(i)] = pr.clearance_m < reach ? 1 : 0;
  }
  cull_ = true;
  double least = resolve_penetration(surfaces, margin);
  iterations_used_ = 0;
  // Inside the static friction cone the proxy keeps its place whatever the loop below would do
  // (apply_friction undoes the tangential part): do not pay for sliding it first. A finger held
  // on bone while the device drifts inside it is the common case.
  if (sticks(previous, device_p_world, surfaces)) {
    cull_ = false;
    return;
  }
  // Sliding under friction, the proxy trails the device by the dynamic cone's radius: walking it
  // farther along the surface only for apply_friction to pull it back would spend every
  // iteration (a finger dragged over bone 3 mm deep walked 16 strides, 4 mm, a cycle: 100 us).
  const double slide_budget_m = slide_budget(previous, device_p_world, surfaces);
  double slid_m = 0.0;
  while (iterations_used_ < params_.max_iterations) {
    ++iterations_used_;
    const Vec3 motion = project_onto_contacts(device_p_world - proxy_world_, contacts());
    const double length = motion.norm();
    // Settled: what is left is below a tenth of the contact tolerance (1 um by default), far
    // under a device's position resolution; chasing it on a curved surface only burns queries.
    if (length < 0.1 * params_.contact_tolerance_m) {
      break;
    }
    // Free space up to the least clearance; in contact, short steps then push back out.
    double step = std::min(length, std::max(least, params_.max_substep_m));
    if (contact_count_ > 0) {
      step = std::min(step, slide_budget_m - slid_m);
      if (!(step > 0.1 * params_.contact_tolerance_m)) {
        break;  // slid as far as friction lets it this cycle
      }
      slid_m += step;
    }
    proxy_world_ += motion * (step / length);
    least = resolve_penetration(surfaces, margin);
  }
  settle_onto_nearest(device_p_world, surfaces, margin);
  apply_friction(previous, device_p_world, surfaces, margin);
  cull_ = false;
}

// haptic path
void GodObject::settle_onto_nearest(const Vec3& device_p_world,
                                    std::span<const ProxySurface> surfaces, double margin_m) {
  for (int pass = 0; pass < 3 && contact_count_ == 0; ++pass) {
    const double clearance = nearest_clearance_m_;
    const Vec3 n = nearest_normal_world_;
    const int s = nearest_surface_;
    // Only just off a surface (within a contact step), and only when the device is beyond it:
    // behind its tangent plane and inside that body (near a convex edge the plane alone would
    // snap a proxy onto a body the device is not in). A proxy in free space with the device
    // beside it is where it should be.
    // An open (two-sided) surface has no inside, and probing it at the device would teach it
    // the device's side: never for those.
    if (!(clearance < params_.max_substep_m) || n.isZero() || s < 0 ||
        surfaces[static_cast<std::size_t>(s)].two_sided ||
        (proxy_world_ - device_p_world).dot(n) <= clearance ||
        !(probe(surfaces[static_cast<std::size_t>(s)], s, device_p_world,
                (device_p_world - proxy_world_).norm() + params_.max_substep_m)
              .clearance_m < 0.0)) {
      return;
    }
    proxy_world_ -= n * clearance;
    (void)resolve_penetration(surfaces, margin_m);
  }
}

// haptic path
std::optional<GodObject::FrictionCone> GodObject::friction_cone(
    const Vec3& previous_proxy_world, const Vec3& device_p_world,
    std::span<const ProxySurface> surfaces) const {
  if (contact_count_ == 0) {
    return std::nullopt;
  }
  const ProxyContact& c = contacts_[0];
  const ContactMaterial* material = surfaces[static_cast<std::size_t>(c.surface)].material;
  if (material == nullptr || material->static_friction <= 0.0) {
    return std::nullopt;
  }
  const Vec3 n = c.normal_world;
  const double depth = (proxy_world_ - device_p_world).dot(n);
  if (depth <= 0.0) {
    return std::nullopt;
  }
  const Vec3 offset = device_p_world - previous_proxy_world;
  const Vec3 tangential = offset - offset.dot(n) * n;
  return FrictionCone{n, tangential, tangential.norm(), material->static_friction * depth,
                      material->dynamic_friction * depth};
}

// haptic path
bool GodObject::sticks(const Vec3& previous_proxy_world, const Vec3& device_p_world,
                       std::span<const ProxySurface> surfaces) const {
  const auto cone = friction_cone(previous_proxy_world, device_p_world, surfaces);
  return cone && cone->tangential_m <= cone->static_radius_m;
}

// haptic path
double GodObject::slide_budget(const Vec3& previous_proxy_world, const Vec3& device_p_world,
                               std::span<const ProxySurface> surfaces) const {
  const auto cone = friction_cone(previous_proxy_world, device_p_world, surfaces);
  if (!cone) {
    return std::numeric_limits<double>::infinity();
  }
  // apply_friction's goal (it still trims what a curved path overshoots), plus the tolerance so
  // rounding never stops the slide short of it.
  return std::max(0.0, cone->tangential_m - cone->dynamic_radius_m) + params_.contact_tolerance_m;
}

// haptic path
void GodObject::apply_friction(const Vec3& previous_proxy_world, const Vec3& device_p_world,
                               std::span<const ProxySurface> surfaces, double margin_m) {
  // Copied out of the contacts: the scans below overwrite them.
  const auto cone = friction_cone(previous_proxy_world, device_p_world, surfaces);
  if (!cone) {
    return;
  }
  const Vec3& n = cone->normal_world;
  const Vec3& tangential = cone->tangential_world;
  const double t_len = cone->tangential_m;
  const Vec3 moved = proxy_world_ - previous_proxy_world;
  const Vec3 moved_t = moved - moved.dot(n) * n;
  if (t_len <= cone->static_radius_m) {
    proxy_world_ -= moved_t;  // stick: inside the friction cone the proxy keeps its place
  } else {
    // Slip: the proxy trails the device by the dynamic friction cone's radius. Friction only
    // holds the proxy back: when the sliding loop has not yet come that far (the device deep in
    // and far ahead), moving it the rest of the way here would be a jump nobody traced, through
    // whatever lies between (it crossed the patellar tendon's edge and left the proxy 2 mm off
    // every surface, the device 15 mm deep).
    const Vec3 goal_t = tangential - tangential * (cone->dynamic_radius_m / t_len);
    const double moved_len = moved_t.norm();
    const double goal_len = goal_t.norm();
    if (goal_len < moved_len) {
      // Back along the way it came (the chord of the traced slide), not to a point off it.
      proxy_world_ -= moved_t * (1.0 - goal_len / moved_len);
    }
  }
  resolve_penetration(surfaces, margin_m);
  // Friction moves the proxy in the contact's tangent plane: over a convex surface that lifts
  // it off (10-40 um a cycle sliding over a patella at 50 mm/s), and the force would vanish for
  // that cycle with the device still inside the bone.
  settle_onto_nearest(device_p_world, surfaces, margin_m);
}

// haptic path
Vec3 proxy_force(const GodObject& proxy, std::span<const ProxySurface> surfaces,
                 const Vec3& device_p_world, const Vec3& device_v_world) {
  if (!proxy.in_contact() || !device_p_world.allFinite()) {
    return Vec3::Zero();
  }
  const ProxyContact& c = proxy.contacts().front();
  const ContactMaterial* material = surfaces[static_cast<std::size_t>(c.surface)].material;
  if (material == nullptr) {
    return Vec3::Zero();
  }
  const Vec3 stretch = proxy.proxy_world() - device_p_world;
  const double depth = stretch.norm();
  if (!(depth > 0.0)) {
    return Vec3::Zero();
  }
  const Vec3 direction = stretch / depth;
  const double approach = device_v_world.allFinite() ? -device_v_world.dot(direction) : 0.0;
  return direction * penalty_force_magnitude(*material, depth, approach);
}

}  // namespace hapsim
