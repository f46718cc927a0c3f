#include "hapsim/deform/point_hash_grid.h"

#include "hapsim/core/error.h"

#include <algorithm>
#include <string>

namespace hapsim {

PointHashGrid::PointHashGrid(std::span<const Vec3> points, double cell_m)
    : points_(points.begin(), points.end()), cell_m_(cell_m) {
  if (!std::isfinite(cell_m_) || cell_m_ <= 0.0) {
    throw Error("PointHashGrid",
                "expected a finite cell size > 0 m, got " + std::to_string(cell_m));
  }
  inv_cell_ = 1.0 / cell_m_;
  Box3 box;
  for (std::size_t i = 0; i < points_.size(); ++i) {
    if (!points_[i].allFinite()) {
      throw Error("PointHashGrid", "point " + std::to_string(i) + " is not finite");
    }
    box.extend(points_[i]);
  }
  if (!points_.empty()) {
    origin_m_ = box.min();
    for (int k = 0; k < 3; ++k) {
      const double cells = std::floor((box.max()[k] - origin_m_[k]) * inv_cell_);
      if (cells > 1e9) {
        throw Error("PointHashGrid", "cell size " + std::to_string(cell_m) +
                                         " m is too small for the points' extent");
      }
      max_cell_[k] = static_cast<std::int32_t>(cells);
    }
  }
  std::uint32_t buckets = 1;
  while (buckets < 2 * points_.size() && buckets < (1u << 30)) {
    buckets <<= 1;
  }
  mask_ = buckets - 1;
  cell_of_point_.assign(points_.size(), Cell{0, 0, 0});
  bucket_start_.assign(static_cast<std::size_t>(buckets) + 1, 0);
  for (std::size_t i = 0; i < points_.size(); ++i) {
    Cell& c = cell_of_point_[i];
    for (int k = 0; k < 3; ++k) {
      const double f = std::floor((points_[i][k] - origin_m_[k]) * inv_cell_);
      c[k] = static_cast<std::int32_t>(std::clamp(f, 0.0, static_cast<double>(max_cell_[k])));
    }
    ++bucket_start_[bucket_of(c) + 1];
  }
  for (std::size_t b = 0; b < buckets; ++b) {
    bucket_start_[b + 1] += bucket_start_[b];
  }
  entries_.resize(points_.size());
  std::vector<std::uint32_t> fill(bucket_start_.begin(), bucket_start_.end() - 1);
  for (std::uint32_t i = 0; i < points_.size(); ++i) {
    entries_[fill[bucket_of(cell_of_point_[i])]++] = i;
  }
}

}  // namespace hapsim
