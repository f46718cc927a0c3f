// A uniform hash grid over a fixed point set (a deformable mesh's rest positions), built once, so
// "which points lie within r of p" costs O(points near p) instead of O(all points). Memory is
// O(points) whatever the extent, because only non-empty cells are stored, in a hash table.
//
// The points are kept sorted by cell ("slots"): a cell's points are one contiguous run of slots,
// positions inline, so a query streams through memory instead of chasing indices, and a caller
// that keeps its own per-point state in slot order (VertexDeflection) reads it the same way.
#pragma once

#include "hapsim/core/types.h"

#include <algorithm>
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
  /// once, in no particular order (index: the point's index in the constructor's span). Falls
  /// back to a linear scan when the query box spans more cells than there are points. haptic
  /// path (no allocation).
  template <class Visit>
  void for_each_within(const Vec3& center, double radius_m, Visit&& visit) const;

  /// Calls visit(first, last) for the slots [first, last) of every non-empty cell that overlaps
  /// the box [lo, hi], each slot at most once (or once with every slot when the box spans more
  /// cells than there are points). Candidates only: the caller tests the distances. haptic path
  template <class Visit>
  void for_each_candidate_run(const Vec3& lo, const Vec3& hi, Visit&& visit) const;
  /// How many cells the box [lo, hi] spans inside the grid (0 when it misses the grid): what
  /// for_each_candidate_run() looks up for it.
  [[nodiscard]] double cells_spanned(const Vec3& lo, const Vec3& hi) const;

  /// The points in slot order (sorted by cell).
  [[nodiscard]] std::span<const Vec3> slot_points() const { return slot_points_; }
  /// Slot → the point's index in the constructor's span.
  [[nodiscard]] std::span<const std::uint32_t> slot_index() const { return slot_index_; }

  [[nodiscard]] double cell_m() const { return cell_m_; }
  [[nodiscard]] std::size_t size() const { return slot_points_.size(); }

 private:
  struct CellRange {
    std::int32_t x = -1;  // -1: empty table entry (cells are >= 0)
    std::int32_t y = 0;
    std::int32_t z = 0;
    std::uint32_t begin = 0;  // slots [begin, end)
    std::uint32_t end = 0;
  };
  [[nodiscard]] std::uint32_t bucket_of(std::int32_t x, std::int32_t y, std::int32_t z) const {
    const auto ux = static_cast<std::uint32_t>(x);
    const auto uy = static_cast<std::uint32_t>(y);
    const auto uz = static_cast<std::uint32_t>(z);
    return ((ux * 73856093u) ^ (uy * 19349663u) ^ (uz * 83492791u)) & mask_;
  }
  /// The cell's slots, or null when the cell is empty. haptic path
  [[nodiscard]] const CellRange* find(std::int32_t x, std::int32_t y, std::int32_t z) const {
    for (std::uint32_t b = bucket_of(x, y, z);; b = (b + 1) & mask_) {
      const CellRange& c = table_[b];
      if (c.x == x && c.y == y && c.z == z) {
        return &c;
      }
      if (c.x < 0) {
        return nullptr;
      }
    }
  }
  /// The cell range of the box [lo, hi] clamped to the grid; false when it misses the grid.
  bool box_cells(const Vec3& lo, const Vec3& hi, std::int32_t (&first)[3], std::int32_t (&last)[3],
                 double& cells) const;

  std::vector<Vec3> slot_points_;
  std::vector<std::uint32_t> slot_index_;
  /// Open addressing (linear probing) over the non-empty cells, at most half full.
  std::vector<CellRange> table_;
  Vec3 origin_m_ = Vec3::Zero();
  std::int32_t max_cell_[3] = {0, 0, 0};
  double cell_m_;
  double inv_cell_;
  std::uint32_t mask_ = 0;
};

inline bool PointHashGrid::box_cells(const Vec3& lo, const Vec3& hi, std::int32_t (&first)[3],
                                     std::int32_t (&last)[3], double& cells) const {
  cells = 1.0;
  for (int k = 0; k < 3; ++k) {
    // Clamp in double: the grid holds every point, so cells outside [0, max] are empty.
    const double l = std::floor((lo[k] - origin_m_[k]) * inv_cell_);
    const double h = std::floor((hi[k] - origin_m_[k]) * inv_cell_);
    if (!(h >= 0.0) || !(l <= max_cell_[k])) {
      return false;
    }
    first[k] = static_cast<std::int32_t>(std::max(l, 0.0));
    last[k] = static_cast<std::int32_t>(std::min(h, static_cast<double>(max_cell_[k])));
    cells *= last[k] - first[k] + 1;
  }
  return true;
}

inline double PointHashGrid::cells_spanned(const Vec3& lo, const Vec3& hi) const {
  std::int32_t first[3], last[3];
  double cells = 0.0;
  return box_cells(lo, hi, first, last, cells) ? cells : 0.0;
}

template <class Visit>
void PointHashGrid::for_each_candidate_run(const Vec3& lo, const Vec3& hi, Visit&& visit) const {
  if (slot_points_.empty() || !lo.allFinite() || !hi.allFinite()) {
    return;
  }
  std::int32_t first[3], last[3];
  double cells = 0.0;
  if (!box_cells(lo, hi, first, last, cells)) {
    return;
  }
  if (cells > static_cast<double>(slot_points_.size())) {
    visit(std::uint32_t{0}, static_cast<std::uint32_t>(slot_points_.size()));
    return;
  }
  for (std::int32_t z = first[2]; z <= last[2]; ++z) {
    for (std::int32_t y = first[1]; y <= last[1]; ++y) {
      for (std::int32_t x = first[0]; x <= last[0]; ++x) {
        if (const CellRange* c = find(x, y, z)) {
          visit(c->begin, c->end);
        }
      }
    }
  }
}

template <class Visit>
void PointHashGrid::for_each_within(const Vec3& center, double radius_m, Visit&& visit) const {
  if (!(radius_m > 0.0) || !center.allFinite()) {
    return;
  }
  const double r2 = radius_m * radius_m;
  const Vec3 extent = Vec3::Constant(radius_m);
  for_each_candidate_run(center - extent, center + extent,
                         [&](std::uint32_t first, std::uint32_t last) {
                           for (std::uint32_t s = first; s < last; ++s) {
                             const double d2 = (slot_points_[s] - center).squaredNorm();
                             if (d2 < r2) {
                               visit(slot_index_[s], d2);
                             }
                           }
                         });
}

}  // namespace hapsim
