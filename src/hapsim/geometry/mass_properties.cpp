#include "hapsim/geometry/mass_properties.h"

#include "hapsim/core/error.h"

#include <array>
#include <cmath>
#include <string>

namespace hapsim {

namespace {

// The per-axis subexpressions of the polynomial integrals over one triangle (w0, w1, w2: the
// triangle's three coordinates on one axis).
struct Sub {
  double f1, f2, f3, g0, g1, g2;
};

Sub subexpressions(double w0, double w1, double w2) {
  const double t0 = w0 + w1;
  const double f1 = t0 + w2;
  const double t1 = w0 * w0;
  const double t2 = t1 + w1 * t0;
  const double f2 = t2 + w2 * f1;
  const double f3 = w0 * t1 + w1 * t2 + w2 * f2;
  return {f1, f2, f3, f2 + w0 * (f1 + w0), f2 + w1 * (f1 + w1), f2 + w2 * (f1 + w2)};
}

}  // namespace

MassProperties mass_properties(const TriangleMesh& mesh) {
  // ∫1, ∫x, ∫y, ∫z, ∫x², ∫y², ∫z², ∫xy, ∫yz, ∫zx over the enclosed volume.
  std::array<double, 10> in{};
  for (const TriangleIndices& t : mesh.triangles) {
    const Vec3& p0 = mesh.vertices[t[0]];
    const Vec3& p1 = mesh.vertices[t[1]];
    const Vec3& p2 = mesh.vertices[t[2]];
    const Vec3 d = (p1 - p0).cross(p2 - p0);
    const Sub x = subexpressions(p0.x(), p1.x(), p2.x());
    const Sub y = subexpressions(p0.y(), p1.y(), p2.y());
    const Sub z = subexpressions(p0.z(), p1.z(), p2.z());
    in[0] += d.x() * x.f1;
    in[1] += d.x() * x.f2;
    in[2] += d.y() * y.f2;
    in[3] += d.z() * z.f2;
    in[4] += d.x() * x.f3;
    in[5] += d.y() * y.f3;
    in[6] += d.z() * z.f3;
    in[7] += d.x() * (p0.y() * x.g0 + p1.y() * x.g1 + p2.y() * x.g2);
    in[8] += d.y() * (p0.z() * y.g0 + p1.z() * y.g1 + p2.z() * y.g2);
    in[9] += d.z() * (p0.x() * z.g0 + p1.x() * z.g1 + p2.x() * z.g2);
  }
  constexpr std::array<double, 10> kScale{1.0 / 6,  1.0 / 24, 1.0 / 24,  1.0 / 24,  1.0 / 60,
                                          1.0 / 60, 1.0 / 60, 1.0 / 120, 1.0 / 120, 1.0 / 120};
  for (std::size_t i = 0; i < in.size(); ++i) {
    in[i] *= kScale[i];
  }
  MassProperties m;
  m.volume_m3 = in[0];
  if (!(m.volume_m3 > 0.0) || !std::isfinite(m.volume_m3)) {
    throw Error("mass properties", "the mesh encloses a volume of " + std::to_string(m.volume_m3) +
                                       " m³: it must be closed and face outward");
  }
  const Vec3 c = Vec3(in[1], in[2], in[3]) / m.volume_m3;
  m.com = c;
  const double v = m.volume_m3;
  Mat3& I = m.inertia_per_density;
  // About the origin, then moved to the centre of mass (parallel axes).
  I(0, 0) = in[5] + in[6] - v * (c.y() * c.y() + c.z() * c.z());
  I(1, 1) = in[4] + in[6] - v * (c.z() * c.z() + c.x() * c.x());
  I(2, 2) = in[4] + in[5] - v * (c.x() * c.x() + c.y() * c.y());
  I(0, 1) = I(1, 0) = -(in[7] - v * c.x() * c.y());
  I(1, 2) = I(2, 1) = -(in[8] - v * c.y() * c.z());
  I(0, 2) = I(2, 0) = -(in[9] - v * c.z() * c.x());
  return m;
}

}  // namespace hapsim
