#include "hapsim/collision/knee_index.h"

#include "hapsim/core/stopwatch.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace hapsim {
namespace {

// Spheres of influence holding one point: a palpating fingertip is inside a handful; the cap
// keeps the deepest ones without allocating.
constexpr std::size_t kMaxCandidates = 32;
// Vertices kept by the angular selection: the three closest plus one spare for degenerate or
// non-enclosing triples.
constexpr int kKeep = 4;
// A triple is degenerate below this |(b−a)×(c−a)| / (longest edge)² (0.5 for a right isosceles
// triangle, 0.87 for an equilateral one).
constexpr double kMinTripleQuality = 0.1;

struct Candidate {
  double depth_m;
  std::uint32_t group;
};

double triple_quality(const Vec3& a, const Vec3& b, const Vec3& c, Vec3* n) {
  *n = (b - a).cross(c - a);
  const double e2 = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  return e2 > 0.0 ? n->norm() / e2 : 0.0;
}

}  // namespace

KneeIndex::KneeIndex(const TriangleMesh& mesh, KneeIndexOptions options)
    : mesh_(&mesh), options_(std::move(options)) {
  Stopwatch clock;
  KneeGrouping grouping = build_knee_groups(mesh, options_.groups);
  const std::size_t nv = mesh.vertex_count();

  vertex_group_ = std::move(grouping.vertex_group);
  radial_dir_.assign(nv, Vec3::UnitX());
  vertex_triangle_.assign(nv, kNoTriangle);
  vertex_fan_begin_.assign(nv + 1, 0);
  for (std::size_t t = mesh.triangle_count(); t-- > 0;) {
    for (std::uint32_t v : mesh.triangles[t]) {
      vertex_triangle_[v] = static_cast<std::uint32_t>(t);
      ++vertex_fan_begin_[v + 1];
    }
  }
  for (std::size_t v = 0; v < nv; ++v) {
    vertex_fan_begin_[v + 1] += vertex_fan_begin_[v];
  }
  vertex_fan_.resize(vertex_fan_begin_.back());
  {
    std::vector<std::uint32_t> fill(vertex_fan_begin_.begin(), vertex_fan_begin_.end() - 1);
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
      for (std::uint32_t v : mesh.triangles[t]) {
        vertex_fan_[fill[v]++] = static_cast<std::uint32_t>(t);
      }
    }
  }

  for (const KneeSegment& s : grouping.segments) {
    segments_.push_back({s.centroid_m, s.radius_m, s.group_begin, s.group_end});
  }
  owned_begin_.push_back(0);
  for (const KneeGroup& kg : grouping.groups) {
    Group g{};
    g.centroid_m = kg.centroid_m;
    g.segment = kg.segment;
    g.entry_begin = static_cast<std::uint32_t>(entry_vertex_.size());
    const auto add = [&](std::uint32_t v) {
      const Vec3 d = mesh.vertices[v] - g.centroid_m;
      const double r = d.norm();
      const Vec3 u = r > 0.0 ? Vec3(d / r) : Vec3::UnitX();
      ux_.push_back(static_cast<float>(u.x()));
      uy_.push_back(static_cast<float>(u.y()));
      uz_.push_back(static_cast<float>(u.z()));
      r_.push_back(r);
      entry_vertex_.push_back(v);
      return u;
    };
    for (std::uint32_t v : kg.owned) {
      radial_dir_[v] = add(v);
      owned_vertices_.push_back(v);
    }
    owned_begin_.push_back(static_cast<std::uint32_t>(owned_vertices_.size()));
    g.entry_owned_end = static_cast<std::uint32_t>(entry_vertex_.size());
    for (std::uint32_t v : kg.halo) {
      add(v);
    }
    g.entry_end = static_cast<std::uint32_t>(entry_vertex_.size());
    Vec3 axis = Vec3::Zero();
    for (std::uint32_t e = g.entry_begin; e < g.entry_end; ++e) {
      axis += Vec3(ux_[e], uy_[e], uz_[e]);
    }
    g.cone_axis = axis.norm() > 1e-9 ? Vec3(axis.normalized()) : Vec3::UnitZ();
    g.cone_cos = 1.0;
    for (std::uint32_t e = g.entry_begin; e < g.entry_end; ++e) {
      g.cone_cos = std::min(g.cone_cos, g.cone_axis.dot(Vec3(ux_[e], uy_[e], uz_[e])));
    }
    g.cone_cos = g.cone_cos - 1e-6;  // float directions
    // The spherical cap through the farthest direction bounds the patch's directions only while
    // it is convex, i.e. smaller than a hemisphere: a wider patch (a whole small closed body,
    // whose mean direction is ~0) can have triangles reaching outside the cap, so no culling.
    if (g.cone_cos <= 0.0) {
      g.cone_cos = -2.0;
    }
    // Error-bound inputs: longest edge, and the largest normal turn between triangles sharing a
    // vertex of the group (how far a plane through nearby vertices can tilt from the surface).
    for (std::uint32_t t : kg.triangles) {
      const auto [a, b, c] = mesh.corners(t);
      g.max_edge_m = std::max({g.max_edge_m, (b - a).norm(), (c - b).norm(), (a - c).norm()});
    }
    groups_.push_back(g);
  }
  // Normal spread per group, through vertex→triangle fans.
  {
    std::vector<Vec3> face_n(mesh.triangle_count());
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
      face_n[t] = mesh.face_normal(t);
    }
    std::vector<double> min_cos_at_vertex(nv, 1.0);
    std::vector<Vec3> first_n(nv, Vec3::Zero());
    std::vector<std::vector<std::uint32_t>> fan(nv);
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
      for (std::uint32_t v : mesh.triangles[t]) {
        fan[v].push_back(static_cast<std::uint32_t>(t));
      }
    }
    for (std::size_t v = 0; v < nv; ++v) {
      for (std::size_t i = 0; i < fan[v].size(); ++i) {
        for (std::size_t j = i + 1; j < fan[v].size(); ++j) {
          min_cos_at_vertex[v] =
              std::min(min_cos_at_vertex[v], face_n[fan[v][i]].dot(face_n[fan[v][j]]));
        }
      }
    }
    for (Group& g : groups_) {
      double min_cos = 1.0;
      for (std::uint32_t e = g.entry_begin; e < g.entry_end; ++e) {
        min_cos = std::min(min_cos, min_cos_at_vertex[entry_vertex_[e]]);
      }
      g.normal_spread_rad = std::acos(std::clamp(min_cos, -1.0, 1.0));
    }
  }
  // CSR vertex → entries, for local refits.
  vertex_entry_begin_.assign(nv + 1, 0);
  for (std::uint32_t v : entry_vertex_) {
    ++vertex_entry_begin_[v + 1];
  }
  for (std::size_t v = 0; v < nv; ++v) {
    vertex_entry_begin_[v + 1] += vertex_entry_begin_[v];
  }
  vertex_entries_.resize(entry_vertex_.size());
  {
    std::vector<std::uint32_t> fill(vertex_entry_begin_.begin(), vertex_entry_begin_.end() - 1);
    for (std::size_t e = 0; e < entry_vertex_.size(); ++e) {
      vertex_entries_[fill[entry_vertex_[e]]++] = static_cast<std::uint32_t>(e);
    }
  }
  refit_bounds_tight();

  stats_.groups = grouping.stats;
  stats_.entries_per_vertex =
      nv > 0 ? static_cast<double>(entry_vertex_.size()) / static_cast<double>(nv) : 0.0;
  stats_.memory_bytes = memory_bytes();
  stats_.build_ms = clock.elapsed_ms();
}

std::span<const std::uint32_t> KneeIndex::group_vertices(std::uint32_t g) const {
  return {owned_vertices_.data() + owned_begin_[g], owned_begin_[g + 1] - owned_begin_[g]};
}

void KneeIndex::refit_bounds_tight() {
  for (Group& g : groups_) {
    double r = 0.0;
    for (std::uint32_t e = g.entry_begin; e < g.entry_end; ++e) {
      r = std::max(r, r_[e]);
    }
    g.radius_m = r;
  }
  for (Segment& s : segments_) {
    // Farthest vertex from the segment centroid: every vertex is an entry of its own group.
    double r = 0.0;
    for (std::uint32_t g = s.group_begin; g < s.group_end; ++g) {
      const Group& grp = groups_[g];
      for (std::uint32_t e = grp.entry_begin; e < grp.entry_owned_end; ++e) {
        r = std::max(r, (mesh_->vertices[entry_vertex_[e]] - s.centroid_m).norm());
      }
    }
    s.radius_m = r;
  }
}

void KneeIndex::refit() {
  for (std::size_t e = 0; e < entry_vertex_.size(); ++e) {
    r_[e] = 0.0;
  }
  for (const Group& g : groups_) {
    for (std::uint32_t e = g.entry_begin; e < g.entry_end; ++e) {
      r_[e] = (mesh_->vertices[entry_vertex_[e]] - g.centroid_m).norm();
    }
  }
  refit_bounds_tight();
}

// haptic path
void KneeIndex::refit_vertices(std::span<const std::uint32_t> moved) {
  for (std::uint32_t v : moved) {
    const Vec3& x = mesh_->vertices[v];
    for (std::uint32_t i = vertex_entry_begin_[v]; i < vertex_entry_begin_[v + 1]; ++i) {
      const std::uint32_t e = vertex_entries_[i];
      // Entries of one vertex belong to different groups; find the group by range (few groups
      // per vertex, so a binary search over groups is not worth it: walk from the owner).
      std::uint32_t g = vertex_group_[v];
      if (e < groups_[g].entry_begin || e >= groups_[g].entry_end) {
        const auto it = std::upper_bound(
            groups_.begin(), groups_.end(), e,
            [](std::uint32_t entry, const Group& grp) { return entry < grp.entry_begin; });
        g = static_cast<std::uint32_t>(it - groups_.begin() - 1);
      }
      Group& grp = groups_[g];
      r_[e] = (x - grp.centroid_m).norm();
      grp.radius_m = std::max(grp.radius_m, r_[e]);
      Segment& s = segments_[grp.segment];
      s.radius_m = std::max(s.radius_m, (x - s.centroid_m).norm());
    }
  }
}

std::size_t KneeIndex::memory_bytes() const {
  return segments_.capacity() * sizeof(Segment) + groups_.capacity() * sizeof(Group) +
         (ux_.capacity() + uy_.capacity() + uz_.capacity()) * sizeof(float) +
         r_.capacity() * sizeof(double) +
         (entry_vertex_.capacity() + vertex_group_.capacity() + vertex_triangle_.capacity() +
          vertex_entry_begin_.capacity() + vertex_entries_.capacity() +
          vertex_fan_begin_.capacity() + vertex_fan_.capacity() + owned_vertices_.capacity() +
          owned_begin_.capacity()) *
             sizeof(std::uint32_t) +
         radial_dir_.capacity() * sizeof(Vec3);
}

// haptic path
bool KneeIndex::plane_for_group(const Vec3& p, std::uint32_t gi, KneeCounters* counters,
                                SurfacePoint* answer, bool* covers, bool use_cone) const {
  const Group& g = groups_[gi];
  Vec3 d = p - g.centroid_m;
  const double dn = d.norm();
  d = dn > 0.0 ? Vec3(d / dn) : Vec3::UnitZ();
  *covers = false;
  if (use_cone && d.dot(g.cone_axis) < g.cone_cos) {
    return false;  // the ray from the centroid through p misses this group's patch
  }
  const float dx = static_cast<float>(d.x());
  const float dy = static_cast<float>(d.y());
  const float dz = static_cast<float>(d.z());
  // The vertices closest in angle = largest dot product of unit directions: keep the top kKeep.
  std::array<float, kKeep> best_dot;
  std::array<std::uint32_t, kKeep> best_e;
  best_dot.fill(-2.0f);
  best_e.fill(g.entry_begin);
  const float* ux = ux_.data();
  const float* uy = uy_.data();
  const float* uz = uz_.data();
  for (std::uint32_t e = g.entry_begin; e < g.entry_end; ++e) {
    const float dot = ux[e] * dx + uy[e] * dy + uz[e] * dz;
    if (dot > best_dot[kKeep - 1]) {
      int k = kKeep - 1;
      while (k > 0 && dot > best_dot[static_cast<std::size_t>(k - 1)]) {
        best_dot[static_cast<std::size_t>(k)] = best_dot[static_cast<std::size_t>(k - 1)];
        best_e[static_cast<std::size_t>(k)] = best_e[static_cast<std::size_t>(k - 1)];
        --k;
      }
      best_dot[static_cast<std::size_t>(k)] = dot;
      best_e[static_cast<std::size_t>(k)] = e;
    }
  }
  if (counters != nullptr) {
    ++counters->groups_visited;
    counters->vertices_scanned += g.entry_end - g.entry_begin;
  }
  // `enclosed`: an enclosing triple next to an owned vertex, i.e. the point's direction falls
  // in this group's own patch, not in the halo that only borders it nor beside the patch.
  const std::size_t found = std::min<std::size_t>(kKeep, g.entry_end - g.entry_begin);

  const auto pos = [&](std::size_t k) -> const Vec3& {
    return mesh_->vertices[entry_vertex_[best_e[k]]];
  };
  const auto dir = [&](std::size_t k) {
    const std::uint32_t e = best_e[k];
    return Vec3(ux[e], uy[e], uz[e]);
  };
  Vec3 normal = Vec3::Zero();
  const Vec3* anchor = nullptr;
  std::uint32_t triangle = vertex_triangle_[entry_vertex_[best_e[0]]];
  bool enclosed = false;
  if (options_.triple_rule == KneeTripleRule::kEnclosingTriangle) {
    // The triangle crossed by the ray from the centroid: its corners, seen from the centroid,
    // wind counter-clockwise around d (all triple products >= 0 for an outward-CCW triangle).
    const TriangleMesh& m = *mesh_;
    for (std::size_t k = 0; k < found && !enclosed; ++k) {
      const std::uint32_t v = entry_vertex_[best_e[k]];
      for (std::uint32_t f = vertex_fan_begin_[v]; f < vertex_fan_begin_[v + 1]; ++f) {
        const std::uint32_t t = vertex_fan_[f];
        const TriangleIndices& tri = m.triangles[t];
        const Vec3 da = m.vertices[tri[0]] - g.centroid_m;
        const Vec3 db = m.vertices[tri[1]] - g.centroid_m;
        const Vec3 dc = m.vertices[tri[2]] - g.centroid_m;
        if (da.cross(db).dot(d) >= 0.0 && db.cross(dc).dot(d) >= 0.0 &&
            dc.cross(da).dot(d) >= 0.0) {
          normal = (db - da).cross(dc - da);
          anchor = &m.vertices[tri[0]];
          triangle = t;
          enclosed = best_e[k] < g.entry_owned_end;
          break;
        }
      }
    }
  }
  if (anchor == nullptr && found >= 3) {
    static constexpr std::array<std::array<std::size_t, 3>, 4> kTriples = {
        {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}}};
    const bool paper = options_.triple_rule == KneeTripleRule::kClosestThree;
    const std::size_t triples = found >= 4 ? 4 : 1;
    Vec3 fallback = Vec3::Zero();
    std::size_t fallback_anchor = 0;
    double fallback_quality = -1.0;
    for (std::size_t t = 0; t < triples; ++t) {
      const auto& [i, j, k] = kTriples[t];
      Vec3 n;
      const double q = triple_quality(pos(i), pos(j), pos(k), &n);
      if (q < kMinTripleQuality) {
        if (q > fallback_quality) {
          fallback_quality = q;
          fallback = n;
          fallback_anchor = i;
        }
        continue;
      }
      if (paper) {
        normal = n;
        anchor = &pos(i);
        enclosed = true;  // the paper has no coverage test beyond the sphere of influence
        break;
      }
      // Does the cone spanned by the three rest directions contain d?
      const Vec3 a = dir(i), b = dir(j), c = dir(k);
      const double s0 = a.cross(b).dot(d), s1 = b.cross(c).dot(d), s2 = c.cross(a).dot(d);
      if ((s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0)) {
        normal = n;
        anchor = &pos(i);
        enclosed = best_e[0] < g.entry_owned_end;
        break;
      }
      if (fallback_quality < 2.0) {
        fallback_quality = 2.0;  // first non-degenerate triple beats any degenerate one
        fallback = n;
        fallback_anchor = i;
      }
    }
    if (anchor == nullptr) {
      normal = fallback;
      anchor = &pos(fallback_anchor);
    }
  }
  if (anchor == nullptr || normal.squaredNorm() == 0.0) {
    // Fewer than three usable vertices: the radial direction stands in for the normal.
    normal = pos(0) - g.centroid_m;
    anchor = &pos(0);
  }
  const Vec3& a = *anchor;
  if ((a - g.centroid_m).dot(normal) < 0.0) {
    normal = -normal;  // outward = away from the centroid, which lies inside the body
  }
  normal.normalize();
  const double sd = (p - a).dot(normal);
  answer->signed_distance = sd;
  answer->normal = normal;
  answer->point = p - sd * normal;
  answer->triangle = triangle;
  *covers = enclosed;
  return true;
}

// haptic path
SurfacePoint KneeIndex::query(const Vec3& p, double margin_m, KneeCounters* counters,
                              std::uint32_t* answered_group) const {
  SurfacePoint outside;   // best answer from a covering group that says "no contact"
  SurfacePoint fallback;  // first answer from a non-covering group
  std::uint32_t outside_group = KneeQueryTrace::kNoGroup;
  std::uint32_t fallback_group = KneeQueryTrace::kNoGroup;
  const auto answered = [answered_group](std::uint32_t g) {
    if (answered_group != nullptr) {
      *answered_group = g;
    }
  };
  // The candidate whose cone the point's direction missed by the least: near a group border the ray
  // from each nearby centroid can pass beside that group's patch (the centroids differ, so the
  // cones leave gaps between them); rather than report "nothing here" for a point right at the
  // surface, its plane is used as a last resort.
  std::uint32_t uncovered = kNoTriangle;
  double uncovered_slack = -kInf;
  for (const Segment& s : segments_) {
    if (counters != nullptr) {
      ++counters->segments_tested;
    }
    const double rs = s.radius_m + margin_m;
    if ((p - s.centroid_m).squaredNorm() > rs * rs) {
      continue;
    }
    std::array<Candidate, kMaxCandidates> cand;
    std::size_t n = 0;
    for (std::uint32_t gi = s.group_begin; gi < s.group_end; ++gi) {
      const Group& g = groups_[gi];
      const double rg = g.radius_m + margin_m;
      const double d2 = (p - g.centroid_m).squaredNorm();
      if (d2 > rg * rg) {
        continue;
      }
      const Candidate c{rg - std::sqrt(d2), gi};
      if (n < kMaxCandidates) {
        cand[n++] = c;
      } else {
        // Full: replace the shallowest if this one is deeper.
        auto* shallow = std::min_element(cand.begin(), cand.end(),
                                         [](auto& x, auto& y) { return x.depth_m < y.depth_m; });
        if (shallow->depth_m < c.depth_m) {
          *shallow = c;
        }
      }
    }
    if (counters != nullptr) {
      counters->group_spheres_tested += s.group_end - s.group_begin;
    }
    // Deepest inside its sphere of influence first (the paper's ranking).
    std::sort(cand.begin(), cand.begin() + static_cast<std::ptrdiff_t>(n),
              [](const Candidate& x, const Candidate& y) { return x.depth_m > y.depth_m; });
    for (std::size_t i = 0; i < n; ++i) {
      SurfacePoint ans;
      bool covers = false;
      if (!plane_for_group(p, cand[i].group, counters, &ans, &covers)) {
        // Keep the group whose cone the direction misses by the least.
        const Group& g = groups_[cand[i].group];
        const double slack = (p - g.centroid_m).normalized().dot(g.cone_axis) - g.cone_cos;
        if (slack > uncovered_slack) {
          uncovered_slack = slack;
          uncovered = cand[i].group;
        }
        continue;
      }
      if (covers) {
        if (ans.signed_distance < 0.0) {
          answered(cand[i].group);
          return ans;  // contact: the point is on the centroid's side of the plane
        }
        if (ans.signed_distance < outside.signed_distance) {
          outside = ans;
          outside_group = cand[i].group;
        }
      } else if (!fallback.found()) {
        fallback = ans;
        fallback_group = cand[i].group;
      }
    }
  }
  if (outside.found()) {
    answered(outside_group);
    return outside;
  }
  if (!fallback.found() && uncovered != kNoTriangle) {
    bool covers = false;
    (void)plane_for_group(p, uncovered, counters, &fallback, &covers, /*use_cone=*/false);
    fallback_group = uncovered;
  }
  answered(fallback.found() ? fallback_group : KneeQueryTrace::kNoGroup);
  return fallback;
}

KneeQueryTrace KneeIndex::trace(const Vec3& p) const {
  KneeQueryTrace t;
  (void)query(p, options_.influence_margin_m, nullptr, &t.group);
  if (t.group == KneeQueryTrace::kNoGroup) {
    return t;
  }
  // The same angular selection as plane_for_group: largest dot product of the rest directions.
  const Group& g = groups_[t.group];
  const Vec3 d = (p - g.centroid_m).normalized();
  const auto dx = static_cast<float>(d.x());
  const auto dy = static_cast<float>(d.y());
  const auto dz = static_cast<float>(d.z());
  std::array<float, 3> best_dot;
  best_dot.fill(-2.0f);
  for (std::uint32_t e = g.entry_begin; e < g.entry_end; ++e) {
    const float dot = ux_[e] * dx + uy_[e] * dy + uz_[e] * dz;
    std::size_t k = std::min<std::size_t>(t.vertex_count, 2);
    if (t.vertex_count == 3 && !(dot > best_dot[2])) {
      continue;
    }
    for (; k > 0 && dot > best_dot[k - 1]; --k) {
      best_dot[k] = best_dot[k - 1];
      t.closest_vertices[k] = t.closest_vertices[k - 1];
    }
    best_dot[k] = dot;
    t.closest_vertices[k] = entry_vertex_[e];
    t.vertex_count = std::min<std::size_t>(t.vertex_count + 1, 3);
  }
  return t;
}

SurfacePoint KneeIndex::closest_point(const Vec3& p, QueryHint* hint) const {
  SurfacePoint sp = query(p, options_.influence_margin_m, nullptr);
  if (hint != nullptr) {
    hint->triangle = sp.triangle;
  }
  return sp;
}

SurfacePoint KneeIndex::closest_point_counted(const Vec3& p, KneeCounters* counters) const {
  return query(p, options_.influence_margin_m, counters);
}

bool KneeIndex::contact_within(const Vec3& p, double radius, SurfacePoint* out,
                               QueryHint* hint) const {
  // Growing the spheres by `radius` only: segments and groups farther than that are culled
  // before any vertex is looked at.
  const SurfacePoint sp = query(p, std::max(radius, 0.0), nullptr);
  if (hint != nullptr) {
    hint->triangle = sp.triangle;
  }
  if (!sp.found() || std::abs(sp.signed_distance) > radius) {
    return false;
  }
  if (out != nullptr) {
    *out = sp;
  }
  return true;
}

double KneeIndex::error_bound_m(double band_m) const {
  // The plane through three vertices near the point's ray differs from the triangle the ray
  // actually crosses by a tilt of at most the local normal spread θ, applied over a lever of
  // at most about two edge lengths (the vertices' distance from the crossing point) plus the
  // point's own distance from the surface: |error| ≲ (2h + band)·sin θ.
  double bound = 0.0;
  for (const Group& g : groups_) {
    const double theta = std::min(g.normal_spread_rad, 0.5 * 3.141592653589793);
    bound = std::max(bound, (2.0 * g.max_edge_m + band_m) * std::sin(theta));
  }
  return bound;
}

}  // namespace hapsim
