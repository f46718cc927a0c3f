// Analytic surfaces with exact answers, as ProximityQuery, for force tests: a half-space and a
// solid sphere. Written independently of the mesh code so the tests check one against the other.
#pragma once

#include "hapsim/collision/proximity_query.h"

#include <cmath>

namespace hapsim::test {

/// The half-space z <= 0 (surface z = 0, outward +z).
class HalfSpace final : public ProximityQuery {
 public:
  SurfacePoint closest_point(const Vec3& p, QueryHint* /*hint*/) const override {
    SurfacePoint s;
    s.point = Vec3(p.x(), p.y(), 0.0);
    s.normal = Vec3::UnitZ();
    s.signed_distance = p.z();
    s.triangle = 0;
    return s;
  }
  bool contact_within(const Vec3& p, double radius, SurfacePoint* out,
                      QueryHint* hint) const override {
    if (std::abs(p.z()) > radius) {
      return false;
    }
    *out = closest_point(p, hint);
    return true;
  }
  void refit() override {}
  std::size_t memory_bytes() const override { return 0; }
  std::string_view method_name() const override { return "half-space"; }
};

/// A solid sphere of radius r at the origin.
class SolidSphere final : public ProximityQuery {
 public:
  explicit SolidSphere(double radius_m) : radius_m_(radius_m) {}
  SurfacePoint closest_point(const Vec3& p, QueryHint* /*hint*/) const override {
    SurfacePoint s;
    const double len = p.norm();
    const Vec3 dir = len > 0.0 ? Vec3(p / len) : Vec3::UnitZ();
    s.point = dir * radius_m_;
    s.normal = dir;
    s.signed_distance = len - radius_m_;
    s.triangle = 0;
    return s;
  }
  bool contact_within(const Vec3& p, double radius, SurfacePoint* out,
                      QueryHint* hint) const override {
    if (std::abs(p.norm() - radius_m_) > radius) {
      return false;
    }
    *out = closest_point(p, hint);
    return true;
  }
  void refit() override {}
  std::size_t memory_bytes() const override { return 0; }
  std::string_view method_name() const override { return "solid-sphere"; }

 private:
  double radius_m_;
};

}  // namespace hapsim::test
