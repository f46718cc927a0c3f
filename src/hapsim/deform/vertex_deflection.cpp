#include "hapsim/deform/vertex_deflection.h"

#include "hapsim/core/error.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>

namespace hapsim {

namespace {

void check_params(const DeflectionParams& p, std::size_t s) {
  const std::string where = "VertexDeflectionOptions.segments[" + std::to_string(s) + "]";
  if (!std::isfinite(p.elasticity_factor) || p.elasticity_factor <= 0.0) {
    throw Error(where + ".elasticity_factor",
                "expected a finite factor > 0, got " + std::to_string(p.elasticity_factor));
  }
  if (std::isnan(p.recovery_time_constant_s) || p.recovery_time_constant_s < 0.0) {
    throw Error(where + ".recovery_time_constant_s",
                "expected a time >= 0 s, got " + std::to_string(p.recovery_time_constant_s));
  }
  if (std::isnan(p.max_recovery_speed_m_per_s) || p.max_recovery_speed_m_per_s <= 0.0) {
    throw Error(where + ".max_recovery_speed_m_per_s",
                "expected a speed > 0 m/s, got " + std::to_string(p.max_recovery_speed_m_per_s));
  }
  if (std::isnan(p.max_deflection_m) || p.max_deflection_m <= 0.0) {
    throw Error(where + ".max_deflection_m",
                "expected a depth > 0 m, got " + std::to_string(p.max_deflection_m));
  }
  if (!std::isfinite(p.rest_tolerance_m) || p.rest_tolerance_m < 0.0) {
    throw Error(where + ".rest_tolerance_m",
                "expected a finite length >= 0 m, got " + std::to_string(p.rest_tolerance_m));
  }
}

/// Angle-weighted normal of vertex v from its incident triangles (as TriangleMesh does).
Vec3 vertex_normal(const TriangleMesh& mesh, std::span<const std::uint32_t> tris, std::uint32_t v) {
  Vec3 sum = Vec3::Zero();
  for (const std::uint32_t t : tris) {
    const TriangleIndices& tri = mesh.triangles[t];
    const int k = tri[0] == v ? 0 : (tri[1] == v ? 1 : 2);
    const Vec3 n = mesh.face_normal(t);
    const Vec3& p = mesh.vertices[v];
    const Vec3 e1 = (mesh.vertices[tri[(k + 1) % 3]] - p).normalized();
    const Vec3 e2 = (mesh.vertices[tri[(k + 2) % 3]] - p).normalized();
    sum += std::acos(std::clamp(e1.dot(e2), -1.0, 1.0)) * n;
  }
  const double len = sum.norm();
  return len > 0.0 && std::isfinite(len) ? Vec3(sum / len) : Vec3::Zero();
}

// (cos(π·t) + 1)/2 = cos²(π·t/2) for u = t² in [0, 1], without sqrt or cos: cos(π/2·√u) is a
// power series in u; terms up to u^8 leave an error below 1e-10 (the next term is
// (π/2)^18/18! < 4e-12), far below anything a vertex position can show. Hot loop of step().
constexpr double half_cos_series_term(int k) {
  double term = 1.0;
  for (int i = 1; i <= k; ++i) {
    term *=
        -(std::numbers::pi * std::numbers::pi / 4.0) / static_cast<double>((2 * i - 1) * (2 * i));
  }
  return term;
}

inline double raised_cosine_of_squared(double u) {
  constexpr double c0 = half_cos_series_term(0), c1 = half_cos_series_term(1),
                   c2 = half_cos_series_term(2), c3 = half_cos_series_term(3),
                   c4 = half_cos_series_term(4), c5 = half_cos_series_term(5),
                   c6 = half_cos_series_term(6), c7 = half_cos_series_term(7),
                   c8 = half_cos_series_term(8);
  const double c =
      c0 + u * (c1 + u * (c2 + u * (c3 + u * (c4 + u * (c5 + u * (c6 + u * (c7 + u * c8)))))));
  return c * c;
}

}  // namespace

double VertexDeflection::deflection_profile_from_squared_m(double distance_sq_m2,
                                                           double penetration_m,
                                                           double zero_distance_m) {
  const double d0_sq = zero_distance_m * zero_distance_m;
  if (!(distance_sq_m2 >= 0.0) || !(distance_sq_m2 < d0_sq) || !(penetration_m > 0.0)) {
    return 0.0;
  }
  return penetration_m * raised_cosine_of_squared(distance_sq_m2 / d0_sq);
}

VertexDeflection::VertexDeflection(TriangleMesh rest_mesh, VertexDeflectionOptions options)
    : mesh_(std::make_unique<TriangleMesh>(std::move(rest_mesh))),
      segment_of_vertex_(std::move(options.segment_of_vertex)),
      segments_(std::move(options.segments)) {
  TriangleMesh& mesh = *mesh_;
  const std::size_t n = mesh.vertex_count();
  if (n >= std::numeric_limits<std::uint32_t>::max()) {
    throw Error("VertexDeflection", "too many vertices for 32-bit indices");
  }
  for (std::size_t v = 0; v < n; ++v) {
    if (!mesh.vertices[v].allFinite()) {
      throw Error("VertexDeflection", "rest vertex " + std::to_string(v) + " is not finite");
    }
  }
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    for (const std::uint32_t v : mesh.triangles[t]) {
      if (v >= n) {
        throw Error("VertexDeflection", "triangle " + std::to_string(t) +
                                            " references missing vertex " + std::to_string(v));
      }
    }
  }
  if (segments_.empty()) {
    segments_.emplace_back();
  }
  for (std::size_t s = 0; s < segments_.size(); ++s) {
    check_params(segments_[s], s);
  }
  if (segment_of_vertex_.empty()) {
    segment_of_vertex_.assign(n, 0);
  } else if (segment_of_vertex_.size() != n) {
    throw Error("VertexDeflectionOptions.segment_of_vertex",
                "expected one segment per vertex (" + std::to_string(n) + "), got " +
                    std::to_string(segment_of_vertex_.size()));
  }
  for (std::size_t v = 0; v < n; ++v) {
    if (segment_of_vertex_[v] >= segments_.size()) {
      throw Error("VertexDeflectionOptions.segment_of_vertex[" + std::to_string(v) + "]",
                  "expected a segment < " + std::to_string(segments_.size()) + ", got " +
                      std::to_string(segment_of_vertex_[v]));
    }
  }

  if (mesh.vertex_normals.size() != n) {
    mesh.compute_vertex_normals();
  }
  rest_ = mesh.vertices;
  if (options.directions.empty()) {
    // A vertex without a normal (unused or only in degenerate triangles) simply stays put.
    direction_.resize(n);
    for (std::size_t v = 0; v < n; ++v) {
      direction_[v] = -mesh.vertex_normals[v];
    }
  } else {
    if (options.directions.size() != n) {
      throw Error("VertexDeflectionOptions.directions",
                  "expected one direction per vertex (" + std::to_string(n) + "), got " +
                      std::to_string(options.directions.size()));
    }
    direction_ = std::move(options.directions);
    for (std::size_t v = 0; v < n; ++v) {
      const double len = direction_[v].norm();
      if (!std::isfinite(len) || len < 1e-12) {
        throw Error("VertexDeflectionOptions.directions[" + std::to_string(v) + "]",
                    "expected a finite, non-zero direction");
      }
      direction_[v] /= len;
    }
  }

  // Vertex → triangle adjacency.
  vertex_tri_start_.assign(n + 1, 0);
  for (const TriangleIndices& tri : mesh.triangles) {
    for (const std::uint32_t v : tri) {
      ++vertex_tri_start_[v + 1];
    }
  }
  for (std::size_t v = 0; v < n; ++v) {
    vertex_tri_start_[v + 1] += vertex_tri_start_[v];
  }
  vertex_tris_.resize(vertex_tri_start_[n]);
  {
    std::vector<std::uint32_t> fill(vertex_tri_start_.begin(), vertex_tri_start_.end() - 1);
    for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
      for (const std::uint32_t v : mesh.triangles[t]) {
        vertex_tris_[fill[v]++] = t;
      }
    }
  }

  double cell_m = options.grid_cell_m;
  if (std::isnan(cell_m) || cell_m < 0.0) {
    throw Error("VertexDeflectionOptions.grid_cell_m",
                "expected a length >= 0 m (0: automatic), got " + std::to_string(cell_m));
  }
  if (cell_m == 0.0) {
    double edge_sum_m = 0.0;
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
      const auto c = mesh.corners(t);
      edge_sum_m += (c[1] - c[0]).norm() + (c[2] - c[1]).norm() + (c[0] - c[2]).norm();
    }
    cell_m = mesh.triangle_count() > 0 ? 2.0 * edge_sum_m / (3.0 * mesh.triangle_count()) : 0.0;
    // A typical press: a query of radius d0 then spans about 5^3 cells instead of (d0/edge)^3
    // (fewer, fuller cells: per cell, step() tests which contacts reach it, then runs through
    // its points without branches).
    const double r_m = std::isfinite(options.typical_contact_radius_m)
                           ? std::max(options.typical_contact_radius_m, 0.0)
                           : 0.0;
    for (const DeflectionParams& p : segments_) {
      const double x_m = std::min(p.max_deflection_m, 0.01);
      cell_m = std::max(cell_m, 0.5 * zero_deflection_distance_m(x_m, r_m, p.elasticity_factor));
    }
    if (!(cell_m > 0.0)) {
      const double diag_m = n > 0 ? mesh.bounds().diagonal().norm() : 0.0;
      cell_m = diag_m > 0.0 ? diag_m / std::cbrt(static_cast<double>(n)) : 1.0;
    }
  }
  grid_ = std::make_unique<PointHashGrid>(rest_, cell_m);

  // Everything the haptic path touches, sized once. The lists are filled once and emptied so
  // their pages are mapped now, not on the first press that reaches them.
  const auto presize = [n](std::vector<std::uint32_t>& list) {
    list.assign(n, 0);
    list.clear();
  };
  slots_.assign(n, Slot{});
  vertex_of_slot_.assign(grid_->slot_index().begin(), grid_->slot_index().end());
  slot_of_vertex_.assign(n, 0);
  for (std::uint32_t s = 0; s < n; ++s) {
    slot_of_vertex_[vertex_of_slot_[s]] = s;
  }
  if (segments_.size() > 1) {
    segment_of_slot_.resize(n);
    for (std::uint32_t s = 0; s < n; ++s) {
      segment_of_slot_[s] = segment_of_vertex_[vertex_of_slot_[s]];
    }
  }
  normal_pending_flag_.assign(n, 0);
  presize(normals_pending_);
  moved_since_normals_flag_.assign(n, 0);
  presize(moved_since_normals_);
  presize(stale_);
  decay_per_segment_.assign(segments_.size(), 0.0);
  triangle_stamp_lazy_.assign(mesh.triangle_count(), 0);
  presize(active_);
  presize(touched_);
  presize(moved_vertices_);
  moved_triangles_.reserve(mesh.triangle_count());
  last_contacts_.reserve(kMaxHeldContacts);
  prepared_.resize(kBatch);
  deepest_scratch_.assign(n, 0.0);
}

double VertexDeflection::deflection_profile_m(double distance_m, double penetration_m,
                                              double zero_distance_m) {
  if (!(distance_m >= 0.0) || !(distance_m < zero_distance_m) || !(penetration_m > 0.0)) {
    return 0.0;
  }
  return 0.5 * penetration_m * (std::cos(std::numbers::pi * distance_m / zero_distance_m) + 1.0);
}

// haptic path
void VertexDeflection::next_stamp() {
  if (++stamp_ == 0) {
    // Wrapped after 2^32 cycles (~50 days at 1 kHz): clear the marks once.
    for (Slot& slot : slots_) {
      slot.stamp = 0;
    }
    stamp_ = 1;
  }
  touched_.clear();
  next_moved_stamp();
}

// haptic path: a new "moved in this step" generation (every step, held or not).
void VertexDeflection::next_moved_stamp() {
  if (++moved_stamp_ == 0) {
    std::fill(triangle_stamp_lazy_.begin(), triangle_stamp_lazy_.end(), 0);
    moved_stamp_ = 1;
  }
  moved_vertices_.clear();
  moved_triangles_.clear();
  moved_triangles_ready_ = false;
}

// haptic path
double VertexDeflection::recovered_gap_m(std::uint32_t segment, double gap_m, double dt_s) const {
  return recover_gap_m(segments_[segment], decay_per_segment_[segment], gap_m, dt_s);
}

double VertexDeflection::recover_gap_m(const DeflectionParams& p, double decay, double gap_m,
                                       double dt_s) {
  double next_m = gap_m * decay;
  // The speed cap slows recovery down, never speeds it past the target.
  next_m = std::max(next_m, gap_m - p.max_recovery_speed_m_per_s * dt_s);
  next_m = std::clamp(next_m, 0.0, gap_m);
  return next_m <= p.rest_tolerance_m ? 0.0 : next_m;
}

// haptic path: the offset only; the position waits for mesh() (listed in stale_ once).
inline void VertexDeflection::set_offset(std::uint32_t slot, double offset_m) {
  Slot& s = slots_[slot];
  if (offset_m == s.offset_m) {
    return;
  }
  s.offset_m = offset_m;
  moved_vertices_.push_back(vertex_of_slot_[slot]);
  if (s.stale_epoch != display_epoch_) {
    s.stale_epoch = display_epoch_;
    stale_.push_back(slot);
  }
}

// haptic path
bool VertexDeflection::same_contacts_as_last(std::span<const DeflectionContact> contacts) const {
  return held_ && contacts.size() == last_contacts_.size() &&
         std::equal(contacts.begin(), contacts.end(), last_contacts_.begin(),
                    [](const DeflectionContact& a, const DeflectionContact& b) {
                      return a.p_mesh == b.p_mesh && a.penetration_m == b.penetration_m &&
                             a.contact_radius_m == b.contact_radius_m && a.segment == b.segment;
                    });
}

// haptic path: a touched slot moves to its target at once when pressed deeper, or recovers
// towards a shallower one.
inline void VertexDeflection::settle(std::uint32_t s, double dt_s) {
  Slot& slot = slots_[s];
  const double target_m = slot.target_m;
  const double current_m = slot.offset_m;
  const double next_m =
      target_m >= current_m
          ? target_m
          : target_m + recovered_gap_m(segments_.size() == 1 ? 0 : segment_of_slot_[s],
                                       current_m - target_m, dt_s);
  settled_ = settled_ && next_m == target_m;
  // Away from rest exactly while listed in active_ (offsets are never negative).
  if (next_m > 0.0 && !(current_m > 0.0)) {
    active_.push_back(s);
  }
  set_offset(s, next_m);
}

// haptic path: every slot within d0 of one of `count` contacts gets its target (deepest wins),
// in one pass over the grid cells of the box [lo, hi] that holds all their reaches. Per cell, only
// the contacts that can reach its box are tried, each over the cell's points in a loop without
// branches, which the compiler packs two points at a time.
// `settle_now`: no other pass reaches these slots this step, so each settles as soon as its cell
// is done (else step() settles the touched list once every pass is done).
void VertexDeflection::press_group(const PreparedContact* first, std::size_t count, const Vec3& lo,
                                   const Vec3& hi, bool settle_now, double dt_s) {
  const double* const xs = grid_->slot_x().data();
  const double* const ys = grid_->slot_y().data();
  const double* const zs = grid_->slot_z().data();
  double* const deepest = deepest_scratch_.data();
  // The deepest δ each of the cell's points gets from contact c (eq. 1 from d² as
  // deflection_profile_from_squared_m; d² as PointHashGrid::squared_distance, so the same
  // vertices and values); < 0 stays "not reached". The profile is evaluated for every point (a
  // finite number past d0 too) and kept only within d0.
  const auto reach = [&]<bool kOneSegment>(const PreparedContact& c, std::uint32_t begin,
                                           std::uint32_t n) {
    const double* const x = xs + begin;
    const double* const y = ys + begin;
    const double* const z = zs + begin;
    const double cx = c.p_mesh.x();
    const double cy = c.p_mesh.y();
    const double cz = c.p_mesh.z();
    for (std::uint32_t i = 0; i < n; ++i) {
      const double dx = x[i] - cx;
      const double dy = y[i] - cy;
      const double dz = z[i] - cz;
      const double d2 = dx * dx + dy * dy + dz * dz;
      const double delta_m = c.x_m * raised_cosine_of_squared(d2 * c.inv_d0_sq);
      const double so_far = deepest[i];
      const double deeper = so_far < delta_m ? delta_m : so_far;  // std::max(so_far, delta_m)
      bool within = d2 < c.r2_m2;
      if constexpr (!kOneSegment) {
        within = within && segment_of_slot_[begin + i] == c.segment;
      }
      deepest[i] = within ? deeper : so_far;
    }
  };
  const bool one_segment = segments_.size() == 1;
  grid_->for_each_candidate_run(
      lo, hi,
      [&](std::uint32_t begin, std::uint32_t end, const Vec3& cell_lo, const Vec3& cell_hi) {
        const std::uint32_t n = end - begin;
        bool reached = false;
        for (std::size_t k = 0; k < count; ++k) {
          const PreparedContact& c = first[k];
          // The box holds every point of the cell, so a contact whose d0 misses the box misses
          // them all (the rounded distances are monotone too: never a reaching contact skipped).
          const Vec3 nearest = c.p_mesh.cwiseMax(cell_lo).cwiseMin(cell_hi);
          if (!((nearest - c.p_mesh).squaredNorm() < c.r2_m2)) {
            continue;
          }
          if (!reached) {
            std::fill_n(deepest, n, -1.0);  // δ itself is never negative
            reached = true;
          }
          if (one_segment) {
            reach.template operator()<true>(c, begin, n);
          } else {
            reach.template operator()<false>(c, begin, n);
          }
        }
        if (!reached) {
          return;
        }
        for (std::uint32_t i = 0; i < n; ++i) {
          if (!(deepest[i] >= 0.0)) {
            continue;
          }
          const std::uint32_t s = begin + i;
          Slot& slot = slots_[s];
          if (settle_now) {
            // The only pass this step: a cell is visited once, so the slot is fresh.
            slot.stamp = stamp_;
            slot.target_m = deepest[i];
            settle(s, dt_s);
          } else if (slot.stamp != stamp_) {
            slot.stamp = stamp_;
            slot.target_m = deepest[i];
            touched_.push_back(s);
          } else {
            slot.target_m = std::max(slot.target_m, deepest[i]);
          }
        }
      });
}

// haptic path: targets of this step's contacts, a batch at a time. Contacts whose boxes overlap
// (fingertips side by side on one muscle) share a pass over the grid, so a vertex several of them
// reach is fetched once.
void VertexDeflection::press(std::span<const DeflectionContact> contacts, double dt_s) {
  std::size_t next = 0;
  while (next < contacts.size()) {
    std::size_t prepared = 0;
    for (; next < contacts.size() && prepared < kBatch; ++next) {
      const DeflectionContact& c = contacts[next];
      if (!c.p_mesh.allFinite() || !std::isfinite(c.penetration_m) ||
          std::isnan(c.contact_radius_m) || c.segment >= segments_.size()) {
        ++rejected_;
        continue;
      }
      const DeflectionParams& p = segments_[c.segment];
      const double x_m = std::min(c.penetration_m, p.max_deflection_m);
      if (!(x_m > 0.0)) {
        continue;
      }
      const double r_m = std::max(c.contact_radius_m, 0.0);
      const double d0_m = zero_deflection_distance_m(x_m, r_m, p.elasticity_factor);
      if (!std::isfinite(d0_m)) {
        ++rejected_;
        continue;
      }
      if (!(d0_m > 0.0)) {
        continue;  // an underflowing depth deflects nothing
      }
      PreparedContact& pc = prepared_[prepared];
      pc.p_mesh = c.p_mesh;
      pc.x_m = x_m;
      pc.r2_m2 = d0_m * d0_m;
      pc.inv_d0_sq = 1.0 / (d0_m * d0_m);
      const Vec3 extent = Vec3::Constant(d0_m);
      pc.lo = c.p_mesh - extent;
      pc.hi = c.p_mesh + extent;
      pc.cells = grid_->cells_spanned(pc.lo, pc.hi);
      pc.segment = c.segment;
      if (pc.cells > 0.0) {
        ++prepared;  // a box outside the grid reaches no vertex
      }
    }
    // Greedy grouping: a contact joins the first group whose box, grown to hold it, spans no
    // more cells than the two boxes apart.
    std::size_t groups = 0;
    for (std::size_t k = 0; k < prepared; ++k) {
      PreparedContact& c = prepared_[k];
      c.group = static_cast<std::uint32_t>(groups);
      for (std::size_t g = 0; g < groups; ++g) {
        Box3& box = group_box_[g];
        Box3 merged = box;
        merged.extend(c.lo);
        merged.extend(c.hi);
        const double cells = grid_->cells_spanned(merged.min(), merged.max());
        if (cells <= group_cells_[g] + c.cells) {
          box = merged;
          group_cells_[g] = cells;
          c.group = static_cast<std::uint32_t>(g);
          break;
        }
      }
      if (c.group == groups) {
        group_box_[groups] = Box3(c.lo, c.hi);
        group_cells_[groups] = c.cells;
        ++groups;
      }
    }
    // Each group's contacts side by side, then one pass per group.
    std::sort(prepared_.begin(), prepared_.begin() + static_cast<std::ptrdiff_t>(prepared),
              [](const PreparedContact& a, const PreparedContact& b) { return a.group < b.group; });
    // One pass in all (one group, one batch: the usual case): slots settle as the pass goes.
    const bool settle_now = groups == 1 && next == contacts.size() && touched_.empty();
    for (std::size_t k = 0; k < prepared;) {
      std::size_t e = k + 1;
      while (e < prepared && prepared_[e].group == prepared_[k].group) {
        ++e;
      }
      const Box3& box = group_box_[prepared_[k].group];
      press_group(prepared_.data() + k, e - k, box.min(), box.max(), settle_now, dt_s);
      k = e;
    }
  }
}

void VertexDeflection::step(std::span<const DeflectionContact> contacts, double dt_s) {
  if (!std::isfinite(dt_s) || dt_s < 0.0) {
    dt_s = 0.0;
  }
  // A held press (bit-identical contacts, every touched vertex already at its target) gives the
  // same targets again: keep last step's marks instead of recomputing thousands of vertices.
  const bool held = same_contacts_as_last(contacts);
  if (held) {
    next_moved_stamp();
  } else {
    next_stamp();
  }
  for (std::size_t s = 0; s < segments_.size(); ++s) {
    const double tau_s = segments_[s].recovery_time_constant_s;
    decay_per_segment_[s] = tau_s > 0.0 ? std::exp(-dt_s / tau_s) : 0.0;
  }
  const bool one_segment = segments_.size() == 1;

  if (!held) {
    const std::size_t rejected_before = rejected_;
    settled_ = true;
    // 1. Target deflection of every vertex near a contact (deepest wins); with a single pass
    // over the grid the touched vertices settle there, else:
    press(contacts, dt_s);
    // 2. Touched vertices: press at once, or recover towards a shallower target.
    for (const std::uint32_t s : touched_) {
      settle(s, dt_s);
    }
    held_ =
        settled_ && rejected_ == rejected_before && contacts.size() <= last_contacts_.capacity();
    if (held_) {
      last_contacts_.assign(contacts.begin(), contacts.end());  // within capacity: no allocation
    }
  }

  // 3. Deformed vertices no contact reaches any more: recover towards rest.
  max_deflection_m_ = 0.0;
  for (std::size_t k = 0; k < active_.size();) {
    const std::uint32_t s = active_[k];
    Slot& slot = slots_[s];
    if (slot.stamp != stamp_) {
      set_offset(s, recovered_gap_m(one_segment ? 0 : segment_of_slot_[s], slot.offset_m, dt_s));
    }
    if (slot.offset_m == 0.0) {
      active_[k] = active_.back();
      active_.pop_back();
      continue;
    }
    max_deflection_m_ = std::max(max_deflection_m_, slot.offset_m);
    ++k;
  }
}

// haptic path: the triangles around the last step's moved vertices, gathered once per step.
std::span<const std::uint32_t> VertexDeflection::moved_triangles() const {
  if (!moved_triangles_ready_) {
    for (const std::uint32_t v : moved_vertices_) {
      for (std::uint32_t e = vertex_tri_start_[v]; e < vertex_tri_start_[v + 1]; ++e) {
        const std::uint32_t t = vertex_tris_[e];
        if (triangle_stamp_lazy_[t] != moved_stamp_) {
          triangle_stamp_lazy_[t] = moved_stamp_;
          moved_triangles_.push_back(t);
        }
      }
    }
    moved_triangles_ready_ = true;
  }
  return moved_triangles_;
}

// Writes the positions the last steps left stale: rest + offset·direction (the rest position
// itself at zero, so a released surface is bit-identical to rest).
void VertexDeflection::sync_positions() const {
  if (stale_.empty()) {
    return;
  }
  std::vector<Vec3>& vertices = mesh_->vertices;
  for (const std::uint32_t s : stale_) {
    const std::uint32_t v = vertex_of_slot_[s];
    const double offset_m = slots_[s].offset_m;
    vertices[v] = offset_m > 0.0 ? Vec3(rest_[v] + offset_m * direction_[v]) : rest_[v];
    if (moved_since_normals_flag_[v] == 0) {
      moved_since_normals_flag_[v] = 1;
      moved_since_normals_.push_back(v);
    }
  }
  stale_.clear();
  if (++display_epoch_ == 0) {
    // Wrapped after 2^32 calls that found something stale: clear the marks once.
    for (const Slot& slot : slots_) {
      slot.stale_epoch = 0;
    }
    display_epoch_ = 1;
  }
}

void VertexDeflection::update_normals() {
  sync_positions();
  TriangleMesh& mesh = *mesh_;
  // A moved vertex changes the normals of every corner of its triangles.
  for (const std::uint32_t m : moved_since_normals_) {
    moved_since_normals_flag_[m] = 0;
    for (std::uint32_t e = vertex_tri_start_[m]; e < vertex_tri_start_[m + 1]; ++e) {
      for (const std::uint32_t v : mesh.triangles[vertex_tris_[e]]) {
        if (normal_pending_flag_[v] == 0) {
          normal_pending_flag_[v] = 1;
          normals_pending_.push_back(v);
        }
      }
    }
  }
  moved_since_normals_.clear();
  for (const std::uint32_t v : normals_pending_) {
    const std::span<const std::uint32_t> tris(vertex_tris_.data() + vertex_tri_start_[v],
                                              vertex_tri_start_[v + 1] - vertex_tri_start_[v]);
    mesh.vertex_normals[v] = vertex_normal(mesh, tris, v);
    normal_pending_flag_[v] = 0;
  }
  normals_pending_.clear();
}

void VertexDeflection::reset() {
  next_stamp();
  held_ = false;
  for (const std::uint32_t s : active_) {
    set_offset(s, 0.0);
  }
  active_.clear();
  max_deflection_m_ = 0.0;
}

}  // namespace hapsim
