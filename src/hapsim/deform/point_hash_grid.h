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

  /// Calls visit(first, last, box_lo, box_hi) for the slots [first, last) of every non-empty
  /// cell that overlaps the box [lo, hi], each slot at most once (or once with every slot when
  /// the box spans more cells than there are points); [box_lo, box_hi] holds every point of the
  /// run (the cell, grown by a rounding margin), so a caller can skip what cannot reach it.
  /// Candidates only: the caller tests the distances. haptic path
  template <class Visit>
  void for_each_candidate_run(const Vec3& lo, const Vec3& hi, Visit&& visit) const;
  /// How many cells the box [lo, hi] spans inside the grid (0 when it misses the grid): what
  /// for_each_candidate_run() looks up for it.
  [[nodiscard]] double cells_spanned(const Vec3& lo, const Vec3& hi) const;

  /// The points' coordinates in slot order (sorted by cell), one array per axis, so a caller
  /// can compute many distances with packed instructions.
  [[nodiscard]] std::span<const double> slot_x() const { return slot_x_; }
  [[nodiscard]] std::span<const double> slot_y() const { return slot_y_; }
  [[nodiscard]] std::span<const double> slot_z() const { return slot_z_; }
  /// |slot s − p|², evaluated as (p − slot s).squaredNorm() is for a Vec3: (dx² + dy²) + dz².
  [[nodiscard]] double squared_distance(std::uint32_t s, const Vec3& p) const {
    const double dx = slot_x_[s] - p.x();
    const double dy = slot_y_[s] - p.y();
    const double dz = slot_z_[s] - p.z();
    return dx * dx + dy * dy + dz * dz;
  }
  /// Slot → the point's index in the constructor's span.
  [[nodiscard]] std::span<const std::uint32_t> slot_index() const { return slot_index_; }

  [[nodiscard]] double cell_m() const { return cell_m_; }
  [[nodiscard]] std::size_t size() const { return slot_index_.size(); }

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

  std::vector<double> slot_x_;
  std::vector<double> slot_y_;
  std::vector<double> slot_z_;
  std::vector<std::uint32_t> slot_index_;
  /// Open addressing (linear probing) over the non-empty cells, at most half full.
  std::vector<CellRange> table_;
  Vec3 origin_m_ = Vec3::Zero();
  /// The points' bounds, grown by margin_m_, and the margin that covers rounding in a point's
  /// cell (1e-9 of the extent: far above the few ulps floor((p - origin)/cell) can be off).
  Vec3 bounds_lo_ = Vec3::Zero();
  Vec3 bounds_hi_ = Vec3::Zero();
  double margin_m_ = 0.0;
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
  if (slot_index_.empty() || !lo.allFinite() || !hi.allFinite()) {
    return;
  }
  std::int32_t first[3], last[3];
  double cells = 0.0;
  if (!box_cells(lo, hi, first, last, cells)) {
    return;
  }
  if (cells > static_cast<double>(slot_index_.size())) {
    visit(std::uint32_t{0}, static_cast<std::uint32_t>(slot_index_.size()), bounds_lo_, bounds_hi_);
    return;
  }
  for (std::int32_t z = first[2]; z <= last[2]; ++z) {
    for (std::int32_t y = first[1]; y <= last[1]; ++y) {
      for (std::int32_t x = first[0]; x <= last[0]; ++x) {
        if (const CellRange* c = find(x, y, z)) {
          const Vec3 cell_lo =
              origin_m_ + cell_m_ * Vec3(static_cast<double>(x), static_cast<double>(y),
                                         static_cast<double>(z));
          visit(c->begin, c->end, Vec3(cell_lo.array() - margin_m_),
                Vec3(cell_lo.array() + (cell_m_ + margin_m_)));
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
                         [&](std::uint32_t first, std::uint32_t last, const Vec3&, const Vec3&) {
                           for (std::uint32_t s = first; s < last; ++s) {
                             const double d2 = squared_distance(s, center);
                             if (d2 < r2) {
                               visit(slot_index_[s], d2);
                             }
                           }
                         });
}

}  // namespace hapsim
