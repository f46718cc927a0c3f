// A uniform hash grid over a fixed point set (a deformable mesh's rest positions), built once, so
// "which points lie within r of p" costs O(points near p) instead of O(all points). Memory is
// O(points) whatever the extent, because cells are hashed rather than stored densely.
#pragma once

#include "hapsim/core/types.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

namespace hapsim {

class PointHashGrid {
 public:
  /// Copies `points` (must be finite); `cell_m` > 0 is the cell edge. Throws hapsim::Error on
  /// non-finite points or a bad cell size.
  PointHashGrid(std::span<const Vec3> points, double cell_m);

  /// Calls visit(index, distance_sq) for every point with |point − center| < radius_m, each point
  /// once, in no particular order. Falls back to a linear scan when the query box spans more
  /// cells than there are points. haptic path (no allocation).
  template <class Visit>
  void for_each_within(const Vec3& center, double radius_m, Visit&& visit) const;

  [[nodiscard]] double cell_m() const { return cell_m_; }
  [[nodiscard]] std::size_t size() const { return points_.size(); }

 private:
  using Cell = std::array<std::int32_t, 3>;
  [[nodiscard]] std::uint32_t bucket_of(const Cell& c) const {
    const auto ux = static_cast<std::uint32_t>(c[0]);
    const auto uy = static_cast<std::uint32_t>(c[1]);
    const auto uz = static_cast<std::uint32_t>(c[2]);
    return ((ux * 73856093u) ^ (uy * 19349663u) ^ (uz * 83492791u)) & mask_;
  }

  std::vector<Vec3> points_;
  std::vector<Cell> cell_of_point_;
  /// CSR: points of bucket b are entries_[bucket_start_[b] .. bucket_start_[b+1]).
  std::vector<std::uint32_t> bucket_start_;
  std::vector<std::uint32_t> entries_;
  Vec3 origin_m_ = Vec3::Zero();
  Cell max_cell_{0, 0, 0};
  double cell_m_;
  double inv_cell_;
  std::uint32_t mask_ = 0;
};

template <class Visit>
void PointHashGrid::for_each_within(const Vec3& center, double radius_m, Visit&& visit) const {
  if (points_.empty() || !(radius_m > 0.0) || !center.allFinite()) {
    return;
  }
  const double r2 = radius_m * radius_m;
  Cell lo{}, hi{};
  double cells = 1.0;
  for (int k = 0; k < 3; ++k) {
    // Clamp in double: the grid holds every point, so cells outside [0, max] are empty.
    const double l = std::floor((center[k] - radius_m - origin_m_[k]) * inv_cell_);
    const double h = std::floor((center[k] + radius_m - origin_m_[k]) * inv_cell_);
    if (h < 0.0 || l > max_cell_[k]) {
      return;
    }
    lo[k] = static_cast<std::int32_t>(std::max(l, 0.0));
    hi[k] = static_cast<std::int32_t>(std::min(h, static_cast<double>(max_cell_[k])));
    cells *= hi[k] - lo[k] + 1;
  }
  if (cells > static_cast<double>(points_.size())) {
    for (std::uint32_t i = 0; i < points_.size(); ++i) {
      const double d2 = (points_[i] - center).squaredNorm();
      if (d2 < r2) {
        visit(i, d2);
      }
    }
    return;
  }
  for (std::int32_t z = lo[2]; z <= hi[2]; ++z) {
    for (std::int32_t y = lo[1]; y <= hi[1]; ++y) {
      for (std::int32_t x = lo[0]; x <= hi[0]; ++x) {
        const Cell cell{x, y, z};
        const std::uint32_t b = bucket_of(cell);
        for (std::uint32_t e = bucket_start_[b]; e < bucket_start_[b + 1]; ++e) {
          const std::uint32_t i = entries_[e];
          // Several cells share a bucket: take a point only from its own cell, so once.
          if (cell_of_point_[i] != cell) {
            continue;
          }
          const double d2 = (points_[i] - center).squaredNorm();
          if (d2 < r2) {
            visit(i, d2);
          }
        }
      }
    }
  }
}

}  // namespace hapsim
