#include "hapsim/collision/minimal_sphere.h"

#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace hapsim {
namespace {

// Points and spheres go through the same algorithm: a point is a sphere of radius 0.
inline const Vec3& center_of(const Vec3& p) {
  return p;
}
inline double radius_of(const Vec3&) {
  return 0.0;
}
inline const Vec3& center_of(const Sphere& s) {
  return s.center;
}
inline double radius_of(const Sphere& s) {
  return s.radius;
}
inline Sphere as_sphere(const Vec3& p) {
  return {p, 0.0};
}
inline Sphere as_sphere(const Sphere& s) {
  return s;
}

// Relative slack of the "already inside" test: rounding in the support solve must not make a
// boundary point look outside (which would only cost time, never correctness).
constexpr double kInsideTol = 1e-12;

inline bool outside(const Sphere& ball, const Sphere& x) {
  const double reach = (x.center - ball.center).norm() + x.radius;
  return reach > ball.radius + kInsideTol * (ball.radius + x.radius);
}

// Points: the same test squared (no square root in the hot loop).
inline bool outside(const Sphere& ball, const Vec3& x) {
  return (x - ball.center).squaredNorm() > ball.radius * ball.radius * (1.0 + 2.0 * kInsideTol);
}

// The smallest sphere enclosing both a and b.
Sphere enclose_pair(const Sphere& a, const Sphere& b) {
  const Vec3 d = b.center - a.center;
  const double dist = d.norm();
  if (dist + b.radius <= a.radius) {
    return a;
  }
  if (dist + a.radius <= b.radius) {
    return b;
  }
  const double radius = 0.5 * (dist + a.radius + b.radius);
  // dist > 0 here: otherwise one would contain the other.
  return {a.center + ((radius - a.radius) / dist) * d, radius};
}

bool encloses(const Sphere& ball, std::span<const Sphere> support) {
  for (const Sphere& s : support) {
    if (outside(ball, s)) {
      return false;
    }
  }
  return true;
}

// A sphere enclosing all of `support` when its tangency system is degenerate (collinear or
// coplanar centres): the smallest candidate of a proper subset that encloses the rest, else a
// greedy pairwise growth (always valid, rarely minimal).
Sphere degenerate_support(std::span<const Sphere> support) {
  const std::size_t k = support.size();
  Sphere best{Vec3::Zero(), kInf};
  std::array<Sphere, 4> subset{};
  for (unsigned mask = 1; mask + 1 < (1U << k); ++mask) {
    std::size_t m = 0;
    for (std::size_t i = 0; i < k; ++i) {
      if ((mask >> i) & 1U) {
        subset[m++] = support[i];
      }
    }
    const std::optional<Sphere> s = sphere_through(std::span<const Sphere>(subset.data(), m));
    if (s && s->radius < best.radius && encloses(*s, support)) {
      best = *s;
    }
  }
  if (best.radius < kInf) {
    return best;
  }
  Sphere grown = support[0];
  for (std::size_t i = 1; i < k; ++i) {
    grown = enclose_pair(grown, support[i]);
  }
  return grown;
}

template <typename T, std::size_t K>
Sphere support_sphere(const std::array<const T*, K>& items) {
  std::array<Sphere, K> s{};
  for (std::size_t i = 0; i < K; ++i) {
    s[i] = as_sphere(*items[i]);
  }
  if constexpr (K == 2) {
    return enclose_pair(s[0], s[1]);
  } else {
    const std::optional<Sphere> exact = sphere_through(std::span<const Sphere>(s.data(), K));
    if (exact && encloses(*exact, s)) {
      return *exact;
    }
    return degenerate_support(s);
  }
}

// Welzl's algorithm unrolled into four nested loops (support sets of at most 4 in 3-D): the
// outer loop keeps the minimal sphere of the prefix; an inner loop runs only when an item falls
// outside, with that item pinned to the boundary.
template <typename T>
Sphere welzl(std::span<T> items) {
  const std::size_t n = items.size();
  if (n == 0) {
    return {};
  }
  Sphere ball = as_sphere(items[0]);
  for (std::size_t i = 1; i < n; ++i) {
    if (!outside(ball, items[i])) {
      continue;
    }
    ball = as_sphere(items[i]);
    for (std::size_t j = 0; j < i; ++j) {
      if (!outside(ball, items[j])) {
        continue;
      }
      ball = support_sphere<T, 2>({&items[i], &items[j]});
      for (std::size_t k = 0; k < j; ++k) {
        if (!outside(ball, items[k])) {
          continue;
        }
        ball = support_sphere<T, 3>({&items[i], &items[j], &items[k]});
        for (std::size_t l = 0; l < k; ++l) {
          if (!outside(ball, items[l])) {
            continue;
          }
          ball = support_sphere<T, 4>({&items[i], &items[j], &items[k], &items[l]});
        }
      }
    }
  }
  // Rounding may leave an item a hair outside: widen so containment is exact as computed.
  ball.radius = std::max(ball.radius, enclosing_radius(ball.center, std::span<const T>(items)));
  return ball;
}

// Deterministic Fisher–Yates (xorshift64*): same tree on every platform and run.
template <typename T>
void shuffle_fixed(std::span<T> items) {
  std::uint64_t state = 0x9E3779B97F4A7C15ULL;
  for (std::size_t i = items.size(); i > 1; --i) {
    state ^= state >> 12;
    state ^= state << 25;
    state ^= state >> 27;
    const std::uint64_t r = state * 0x2545F4914F6CDD1DULL;
    std::swap(items[i - 1], items[static_cast<std::size_t>(r % i)]);
  }
}

}  // namespace

std::optional<Sphere> sphere_through(std::span<const Sphere> support) {
  const std::size_t k = support.size();
  if (k == 0 || k > 4) {
    return std::nullopt;
  }
  if (k == 1) {
    return support[0];
  }
  // Centre c = c0 + Σ λ_j d_j (d_j = c_j − c0) with |c − c_j| = R − r_j for all j. Subtracting
  // the j = 0 equation from the others is linear in (λ, R): G λ = e + R f, G_jl = 2 d_j·d_l.
  // Then λ = α + R β, c − c0 = u + R v, and |u + R v|² = (R − r0)² is a quadratic in R.
  const Vec3& c0 = support[0].center;
  const double r0 = support[0].radius;
  const std::size_t m = k - 1;
  std::array<Vec3, 3> d;
  Eigen::Matrix3d gram = Eigen::Matrix3d::Identity();
  Vec3 e = Vec3::Zero();
  Vec3 f = Vec3::Zero();
  double max_radius = r0;
  for (std::size_t j = 0; j < m; ++j) {
    const Sphere& s = support[j + 1];
    d[j] = s.center - c0;
    e[static_cast<Eigen::Index>(j)] = d[j].squaredNorm() - s.radius * s.radius + r0 * r0;
    f[static_cast<Eigen::Index>(j)] = 2.0 * (s.radius - r0);
    max_radius = std::max(max_radius, s.radius);
  }
  double diag_product = 1.0;
  for (std::size_t j = 0; j < m; ++j) {
    for (std::size_t l = 0; l < m; ++l) {
      gram(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(l)) = 2.0 * d[j].dot(d[l]);
    }
    diag_product *= gram(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(j));
  }
  // det(G)/Π G_jj is a product of squared sines of the angles between the d_j: ~0 means the
  // centres are (nearly) collinear/coplanar or coincide, and the system has no unique answer.
  if (!(diag_product > 0.0) || !(std::abs(gram.determinant()) > 1e-12 * diag_product)) {
    return std::nullopt;
  }
  const Eigen::Matrix3d inv = gram.inverse();  // identity-padded rows decouple
  const Vec3 alpha = inv * e;
  const Vec3 beta = inv * f;
  Vec3 u = Vec3::Zero();
  Vec3 v = Vec3::Zero();
  for (std::size_t j = 0; j < m; ++j) {
    u += alpha[static_cast<Eigen::Index>(j)] * d[j];
    v += beta[static_cast<Eigen::Index>(j)] * d[j];
  }
  const double qa = v.squaredNorm() - 1.0;
  const double qb = 2.0 * (u.dot(v) + r0);
  const double qc = u.squaredNorm() - r0 * r0;
  std::array<double, 2> roots{kInf, kInf};
  if (std::abs(qa) < 1e-14) {
    if (qb != 0.0) {
      roots[0] = -qc / qb;
    }
  } else {
    double disc = qb * qb - 4.0 * qa * qc;
    if (disc < 0.0) {
      if (disc < -1e-12 * qb * qb) {
        return std::nullopt;
      }
      disc = 0.0;
    }
    // Stable quadratic formula (no cancellation in either root).
    const double q = -0.5 * (qb + std::copysign(std::sqrt(disc), qb));
    roots[0] = q / qa;
    roots[1] = q != 0.0 ? qc / q : roots[0];
  }
  const double floor_radius = max_radius - 1e-12 * (max_radius + 1.0);
  double radius = kInf;
  for (double r : roots) {
    if (std::isfinite(r) && r >= floor_radius && r >= 0.0 && r < radius) {
      radius = r;
    }
  }
  if (!std::isfinite(radius)) {
    return std::nullopt;
  }
  radius = std::max(radius, max_radius);
  return Sphere{c0 + u + radius * v, radius};
}

double enclosing_radius(const Vec3& center, std::span<const Vec3> points) {
  double r2 = 0.0;
  for (const Vec3& p : points) {
    r2 = std::max(r2, (p - center).squaredNorm());
  }
  return std::sqrt(r2);
}

double enclosing_radius(const Vec3& center, std::span<const Sphere> spheres) {
  double r = 0.0;
  for (const Sphere& s : spheres) {
    r = std::max(r, (s.center - center).norm() + s.radius);
  }
  return r;
}

Sphere triangle_sphere(const Vec3& a, const Vec3& b, const Vec3& c) {
  // Obtuse or right at a corner: the opposite (longest) edge's diameter sphere.
  const Vec3 ab = b - a;
  const Vec3 ac = c - a;
  const Vec3 bc = c - b;
  Sphere s;
  if (ab.dot(ac) <= 0.0) {
    s = {0.5 * (b + c), 0.0};
  } else if (-ab.dot(bc) <= 0.0) {
    s = {0.5 * (a + c), 0.0};
  } else if (ac.dot(bc) <= 0.0) {
    s = {0.5 * (a + b), 0.0};
  } else {
    // Acute: the circumcircle (Ericson, Real-Time Collision Detection §4.3.4).
    const Vec3 n = ab.cross(ac);
    const double n2 = n.squaredNorm();
    if (n2 > 0.0) {
      s.center = a + (ac.squaredNorm() * n.cross(ab) + ab.squaredNorm() * ac.cross(n)) / (2.0 * n2);
    } else {
      s.center = (a + b + c) / 3.0;
    }
  }
  // Widen to the corners as computed, so containment holds exactly whatever the rounding.
  s.radius = std::sqrt(std::max(
      {(a - s.center).squaredNorm(), (b - s.center).squaredNorm(), (c - s.center).squaredNorm()}));
  return s;
}

Sphere minimal_sphere_inplace(std::span<Vec3> points, bool shuffle) {
  if (shuffle) {
    shuffle_fixed(points);
  }
  return welzl(points);
}

Sphere minimal_sphere(std::span<const Vec3> points) {
  std::vector<Vec3> copy(points.begin(), points.end());
  return minimal_sphere_inplace(copy, true);
}

Sphere enclosing_sphere_inplace(std::span<Sphere> spheres) {
  return welzl(spheres);
}

Sphere enclosing_sphere(std::span<const Sphere> spheres) {
  if (spheres.size() <= 64) {
    std::array<Sphere, 64> copy;
    std::copy(spheres.begin(), spheres.end(), copy.begin());
    return welzl(std::span<Sphere>(copy.data(), spheres.size()));
  }
  std::vector<Sphere> copy(spheres.begin(), spheres.end());
  shuffle_fixed(std::span<Sphere>(copy));
  return welzl(std::span<Sphere>(copy));
}

Sphere ritter_sphere(std::span<const Vec3> points) {
  if (points.empty()) {
    return {};
  }
  const auto farthest_from = [&](const Vec3& q) {
    std::size_t best = 0;
    double best_d2 = -1.0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const double d2 = (points[i] - q).squaredNorm();
      if (d2 > best_d2) {
        best_d2 = d2;
        best = i;
      }
    }
    return best;
  };
  const Vec3& y = points[farthest_from(points[0])];
  const Vec3& z = points[farthest_from(y)];
  Sphere ball = enclose_pair({y, 0.0}, {z, 0.0});
  for (const Vec3& p : points) {
    ball = enclose_pair(ball, {p, 0.0});
  }
  ball.radius = std::max(ball.radius, enclosing_radius(ball.center, points));
  return ball;
}

}  // namespace hapsim
