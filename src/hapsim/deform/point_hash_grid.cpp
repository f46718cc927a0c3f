#include "hapsim/deform/point_hash_grid.h"

#include "hapsim/core/error.h"

#include <algorithm>
#include <array>
#include <limits>
#include <numeric>
#include <string>

namespace hapsim {

PointHashGrid::PointHashGrid(std::span<const Vec3> points, double cell_m) : cell_m_(cell_m) {
  if (!std::isfinite(cell_m_) || cell_m_ <= 0.0) {
    throw Error("PointHashGrid",
                "expected a finite cell size > 0 m, got " + std::to_string(cell_m));
  }
  if (points.size() >= std::numeric_limits<std::uint32_t>::max() / 2) {
    throw Error("PointHashGrid", "too many points for 32-bit indices");
  }
  inv_cell_ = 1.0 / cell_m_;
  Box3 box;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) {
      throw Error("PointHashGrid", "point " + std::to_string(i) + " is not finite");
    }
    box.extend(points[i]);
  }
  if (!points.empty()) {
    origin_m_ = box.min();
    margin_m_ = 1e-9 * std::max(box.diagonal().maxCoeff(), cell_m_);
    bounds_lo_ = Vec3(box.min().array() - margin_m_);
    bounds_hi_ = Vec3(box.max().array() + margin_m_);
    for (int k = 0; k < 3; ++k) {
      const double cells = std::floor((box.max()[k] - origin_m_[k]) * inv_cell_);
      if (cells > 1e9) {
        throw Error("PointHashGrid", "cell size " + std::to_string(cell_m) +
                                         " m is too small for the points' extent");
      }
      max_cell_[k] = static_cast<std::int32_t>(cells);
    }
  }

  // Each point's cell, then the points sorted by cell (z, y, x; ties by index: deterministic).
  using Cell = std::array<std::int32_t, 3>;
  std::vector<Cell> cell_of_point(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      const double f = std::floor((points[i][k] - origin_m_[k]) * inv_cell_);
      cell_of_point[i][static_cast<std::size_t>(k)] =
          static_cast<std::int32_t>(std::clamp(f, 0.0, static_cast<double>(max_cell_[k])));
    }
  }
  slot_index_.resize(points.size());
  std::iota(slot_index_.begin(), slot_index_.end(), 0u);
  std::sort(slot_index_.begin(), slot_index_.end(), [&](std::uint32_t a, std::uint32_t b) {
    const Cell& ca = cell_of_point[a];
    const Cell& cb = cell_of_point[b];
    if (ca[2] != cb[2]) {
      return ca[2] < cb[2];
    }
    if (ca[1] != cb[1]) {
      return ca[1] < cb[1];
    }
    if (ca[0] != cb[0]) {
      return ca[0] < cb[0];
    }
    return a < b;
  });
  slot_x_.resize(points.size());
  slot_y_.resize(points.size());
  slot_z_.resize(points.size());
  std::size_t cell_count = 0;
  for (std::size_t s = 0; s < points.size(); ++s) {
    const Vec3& p = points[slot_index_[s]];
    slot_x_[s] = p.x();
    slot_y_[s] = p.y();
    slot_z_[s] = p.z();
    if (s == 0 || cell_of_point[slot_index_[s]] != cell_of_point[slot_index_[s - 1]]) {
      ++cell_count;
    }
  }

  std::uint32_t buckets = 1;
  while (buckets < 2 * cell_count) {
    buckets <<= 1;
  }
  mask_ = buckets - 1;
  table_.assign(buckets, CellRange{});
  for (std::size_t s = 0; s < points.size();) {
    const Cell& c = cell_of_point[slot_index_[s]];
    std::size_t e = s + 1;
    while (e < points.size() && cell_of_point[slot_index_[e]] == c) {
      ++e;
    }
    std::uint32_t b = bucket_of(c[0], c[1], c[2]);
    while (table_[b].x >= 0) {
      b = (b + 1) & mask_;
    }
    table_[b] =
        CellRange{c[0], c[1], c[2], static_cast<std::uint32_t>(s), static_cast<std::uint32_t>(e)};
    s = e;
  }
}

}  // namespace hapsim
