#include "hapsim/collision/knee_groups.h"

#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/core/stopwatch.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>

namespace hapsim {
namespace {

using Feature = Eigen::Matrix<double, 6, 1>;

// splitmix64: a tiny portable generator, so groups are identical on every standard library.
struct SplitMix {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double uniform01() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
};

// Compressed adjacency (CSR): items of key k are items[begin[k] .. begin[k+1]).
struct Csr {
  std::vector<std::uint32_t> begin;
  std::vector<std::uint32_t> items;
  [[nodiscard]] std::size_t size(std::size_t k) const { return begin[k + 1] - begin[k]; }
  [[nodiscard]] const std::uint32_t* data(std::size_t k) const { return items.data() + begin[k]; }
};

Csr vertex_triangles(const TriangleMesh& mesh) {
  Csr csr;
  csr.begin.assign(mesh.vertex_count() + 1, 0);
  for (const TriangleIndices& t : mesh.triangles) {
    for (std::uint32_t v : t) {
      ++csr.begin[v + 1];
    }
  }
  std::partial_sum(csr.begin.begin(), csr.begin.end(), csr.begin.begin());
  csr.items.resize(csr.begin.back());
  std::vector<std::uint32_t> fill(csr.begin.begin(), csr.begin.end() - 1);
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    for (std::uint32_t v : mesh.triangles[t]) {
      csr.items[fill[v]++] = static_cast<std::uint32_t>(t);
    }
  }
  return csr;
}

std::uint32_t find_root(std::vector<std::uint32_t>& parent, std::uint32_t v) {
  while (parent[v] != v) {
    parent[v] = parent[parent[v]];
    v = parent[v];
  }
  return v;
}

// Lloyd's k-means with k-means++ seeding on `points`; returns a label per point in [0, k).
std::vector<std::uint32_t> kmeans(const std::vector<Feature>& points, std::size_t k, int iterations,
                                  SplitMix& rng) {
  const std::size_t n = points.size();
  k = std::clamp<std::size_t>(k, 1, std::max<std::size_t>(n, 1));
  std::vector<Feature> centers;
  centers.reserve(k);
  centers.push_back(points[std::min<std::size_t>(n - 1, rng.next() % n)]);
  std::vector<double> d2(n, kInf);
  while (centers.size() < k) {
    double total = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      d2[i] = std::min(d2[i], (points[i] - centers.back()).squaredNorm());
      total += d2[i];
    }
    double pick = rng.uniform01() * total;
    std::size_t chosen = n - 1;
    for (std::size_t i = 0; i < n; ++i) {
      pick -= d2[i];
      if (pick <= 0.0) {
        chosen = i;
        break;
      }
    }
    centers.push_back(points[chosen]);
  }
  std::vector<std::uint32_t> label(n, 0);
  std::vector<Feature> sum(k);
  std::vector<std::size_t> count(k);
  for (int it = 0; it < std::max(iterations, 1); ++it) {
    bool changed = (it == 0);
    for (std::size_t i = 0; i < n; ++i) {
      double best = kInf;
      std::uint32_t best_c = 0;
      for (std::size_t c = 0; c < k; ++c) {
        const double d = (points[i] - centers[c]).squaredNorm();
        if (d < best) {
          best = d;
          best_c = static_cast<std::uint32_t>(c);
        }
      }
      changed = changed || (label[i] != best_c);
      label[i] = best_c;
    }
    if (!changed) {
      break;
    }
    std::fill(sum.begin(), sum.end(), Feature::Zero());
    std::fill(count.begin(), count.end(), 0);
    for (std::size_t i = 0; i < n; ++i) {
      sum[label[i]] += points[i];
      ++count[label[i]];
    }
    for (std::size_t c = 0; c < k; ++c) {
      if (count[c] > 0) {
        centers[c] = sum[c] / static_cast<double>(count[c]);
      }
    }
  }
  return label;
}

class GroupBuilder {
 public:
  GroupBuilder(const TriangleMesh& mesh, const KneeGroupOptions& options)
      : mesh_(mesh), options_(options), vt_(vertex_triangles(mesh)), bvh_(mesh) {
    // Area-weighted vertex normals: only the k-means feature and the pull-in direction use them.
    normals_.assign(mesh.vertex_count(), Vec3::Zero());
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
      const Vec3 n = mesh.face_normal_area2(t);
      for (std::uint32_t v : mesh.triangles[t]) {
        normals_[v] += n;
      }
    }
    for (Vec3& n : normals_) {
      const double len = n.norm();
      n = len > 0.0 ? Vec3(n / len) : Vec3::Zero();
    }
    owner_.assign(mesh.vertex_count(), kNoTriangle);
  }

  KneeGrouping build() {
    Stopwatch clock;
    KneeGrouping out;
    const std::vector<std::vector<std::uint32_t>> components = segments_of_mesh();
    SplitMix rng{options_.seed};
    for (std::size_t s = 0; s < components.size(); ++s) {
      report_progress(options_.progress, "knee groups",
                      static_cast<double>(s) / static_cast<double>(components.size()));
      build_segment(components[s], static_cast<std::uint32_t>(s), rng, out);
    }
    out.vertex_group.assign(mesh_.vertex_count(), 0);
    for (std::size_t g = 0; g < out.groups.size(); ++g) {
      for (std::uint32_t v : out.groups[g].owned) {
        out.vertex_group[v] = static_cast<std::uint32_t>(g);
      }
    }
    KneeGroupStats& st = out.stats;
    st.segments = out.segments.size();
    st.groups = out.groups.size();
    st.vertices_per_group_min = std::numeric_limits<std::size_t>::max();
    std::size_t total = 0;
    for (const KneeGroup& g : out.groups) {
      st.vertices_per_group_min = std::min(st.vertices_per_group_min, g.owned.size());
      st.vertices_per_group_max = std::max(st.vertices_per_group_max, g.owned.size());
      total += g.owned.size();
      st.non_star_after_split += g.star_shaped ? 0 : 1;
    }
    if (out.groups.empty()) {
      st.vertices_per_group_min = 0;
    } else {
      st.vertices_per_group_mean =
          static_cast<double>(total) / static_cast<double>(out.groups.size());
    }
    st.non_star_before_split = non_star_before_;
    st.splits = splits_;
    st.centroids_pulled_inside = pulled_inside_;
    st.centroids_outside = outside_;
    st.build_ms = clock.elapsed_ms();
    report_progress(options_.progress, "knee groups", 1.0);
    return out;
  }

 private:
  // Connected components of the triangle graph (isolated vertices form their own segment).
  std::vector<std::vector<std::uint32_t>> segments_of_mesh() const {
    const std::size_t n = mesh_.vertex_count();
    std::vector<std::uint32_t> parent(n);
    std::iota(parent.begin(), parent.end(), 0U);
    for (const TriangleIndices& t : mesh_.triangles) {
      const std::uint32_t a = find_root(parent, t[0]);
      parent[find_root(parent, t[1])] = a;
      parent[find_root(parent, t[2])] = a;
    }
    std::vector<std::uint32_t> index_of_root(n, kNoTriangle);
    std::vector<std::vector<std::uint32_t>> comps;
    for (std::uint32_t v = 0; v < n; ++v) {
      const std::uint32_t r = find_root(parent, v);
      if (index_of_root[r] == kNoTriangle) {
        index_of_root[r] = static_cast<std::uint32_t>(comps.size());
        comps.emplace_back();
      }
      comps[index_of_root[r]].push_back(v);
    }
    return comps;
  }

  void build_segment(const std::vector<std::uint32_t>& verts, std::uint32_t segment_id,
                     SplitMix& rng, KneeGrouping& out) {
    KneeSegment seg;
    for (std::uint32_t v : verts) {
      seg.centroid_m += mesh_.vertices[v];
    }
    seg.centroid_m /= static_cast<double>(verts.size());
    double area = 0.0;
    for (std::uint32_t v : verts) {
      seg.radius_m = std::max(seg.radius_m, (mesh_.vertices[v] - seg.centroid_m).norm());
      for (std::size_t i = 0; i < vt_.size(v); ++i) {
        area += mesh_.face_normal_area2(vt_.data(v)[i]).norm() / 6.0;  // each tri counted 3x
      }
    }
    const std::size_t target = std::max<std::size_t>(options_.target_vertices_per_group, 1);
    const std::size_t k = std::max<std::size_t>(1, (verts.size() + target / 2) / target);
    // Expected group radius: a disc of 1/k of the segment's area.
    normal_scale_ =
        options_.normal_weight * std::sqrt(area / (static_cast<double>(k) * std::numbers::pi));

    std::vector<std::vector<std::uint32_t>> work = cluster(verts, k, rng);
    seg.group_begin = static_cast<std::uint32_t>(out.groups.size());
    // Splitting: failing groups are cut in two until star-shaped, small, or out of rounds.
    std::vector<KneeGroup> done;
    for (int round = 0; !work.empty(); ++round) {
      std::vector<std::vector<std::uint32_t>> next;
      for (std::vector<std::uint32_t>& owned : work) {
        KneeGroup g = make_group(std::move(owned), segment_id);
        if (round == 0 && !g.star_shaped) {
          ++non_star_before_;
        }
        if (!g.star_shaped && round < options_.max_split_rounds &&
            g.owned.size() >= 2 * options_.min_group_vertices) {
          ++splits_;
          for (std::vector<std::uint32_t>& part : cluster(g.owned, 2, rng)) {
            next.push_back(std::move(part));
          }
          continue;
        }
        done.push_back(std::move(g));
      }
      work = std::move(next);
    }
    for (KneeGroup& g : done) {
      count_centroid(g);
      out.groups.push_back(std::move(g));
    }
    seg.group_end = static_cast<std::uint32_t>(out.groups.size());
    out.segments.push_back(seg);
  }

  // k-means on (position, scaled normal), then each cluster cut into its surface-connected parts
  // (k-means in space can join patches that only touch through the body).
  std::vector<std::vector<std::uint32_t>> cluster(const std::vector<std::uint32_t>& verts,
                                                  std::size_t k, SplitMix& rng) {
    std::vector<Feature> features(verts.size());
    for (std::size_t i = 0; i < verts.size(); ++i) {
      features[i].head<3>() = mesh_.vertices[verts[i]];
      features[i].tail<3>() = normal_scale_ * normals_[verts[i]];
    }
    const std::vector<std::uint32_t> label = kmeans(features, k, options_.kmeans_iterations, rng);
    // Connected parts: flood fill through triangles within the same label.
    for (std::size_t i = 0; i < verts.size(); ++i) {
      owner_[verts[i]] = label[i];
    }
    std::vector<std::vector<std::uint32_t>> parts;
    std::vector<std::uint32_t> stack;
    for (std::size_t i = 0; i < verts.size(); ++i) {
      if (owner_[verts[i]] == kNoTriangle) {
        continue;  // already placed in a part
      }
      const std::uint32_t lab = owner_[verts[i]];
      parts.emplace_back();
      stack.push_back(verts[i]);
      owner_[verts[i]] = kNoTriangle;
      while (!stack.empty()) {
        const std::uint32_t v = stack.back();
        stack.pop_back();
        parts.back().push_back(v);
        for (std::size_t j = 0; j < vt_.size(v); ++j) {
          for (std::uint32_t w : mesh_.triangles[vt_.data(v)[j]]) {
            if (owner_[w] == lab) {
              owner_[w] = kNoTriangle;
              stack.push_back(w);
            }
          }
        }
      }
      std::sort(parts.back().begin(), parts.back().end());
    }
    return parts;
  }

  KneeGroup make_group(std::vector<std::uint32_t> owned, std::uint32_t segment_id) {
    KneeGroup g;
    g.segment = segment_id;
    g.owned = std::move(owned);
    for (std::uint32_t v : g.owned) {
      owner_[v] = 1;  // mark
    }
    for (std::uint32_t v : g.owned) {
      for (std::size_t j = 0; j < vt_.size(v); ++j) {
        g.triangles.push_back(vt_.data(v)[j]);
      }
    }
    std::sort(g.triangles.begin(), g.triangles.end());
    g.triangles.erase(std::unique(g.triangles.begin(), g.triangles.end()), g.triangles.end());
    for (std::uint32_t t : g.triangles) {
      for (std::uint32_t w : mesh_.triangles[t]) {
        if (owner_[w] != 1) {
          g.halo.push_back(w);
        }
      }
    }
    std::sort(g.halo.begin(), g.halo.end());
    g.halo.erase(std::unique(g.halo.begin(), g.halo.end()), g.halo.end());
    for (std::uint32_t v : g.owned) {
      owner_[v] = kNoTriangle;
    }
    place_centroid(g);
    return g;
  }

  // The paper needs every group centroid inside the segment, and radial directions roughly
  // normal to the surface: try centroids below the patch's mean at depths proportional to the
  // patch radius, keep the first that is inside, has every triangle facing away from it and
  // sees every vertex of the patch through the interior (see sees()); otherwise the inside one
  // with the fewest failures. Facing away alone is not enough: on a wavy surface a deep centroid
  // can face a patch across a neighbouring bulge, and a ray from it then leaves the body, comes
  // back in and crosses the patch, so a point outside the body would read as deep inside.
  void place_centroid(KneeGroup& g) const {
    Vec3 mean = Vec3::Zero();
    for (std::uint32_t v : g.owned) {
      mean += mesh_.vertices[v];
    }
    mean /= static_cast<double>(g.owned.size());
    Vec3 normal_sum = Vec3::Zero();
    double area2 = 0.0;
    double min_edge = kInf;
    for (std::uint32_t t : g.triangles) {
      const Vec3 n = mesh_.face_normal_area2(t);
      normal_sum += n;
      area2 += n.norm();
      const auto [a, b, c] = mesh_.corners(t);
      min_edge = std::min({min_edge, (b - a).norm(), (c - b).norm(), (a - c).norm()});
    }
    double rho = 0.0;
    for (const auto* list : {&g.owned, &g.halo}) {
      for (std::uint32_t v : *list) {
        rho = std::max(rho, (mesh_.vertices[v] - mean).norm());
      }
    }
    // A ray that reaches within this distance of a vertex has reached it (nothing else of the
    // surface is that close to a vertex on a mesh without near-degenerate triangles).
    const double reach = std::max(0.01 * (std::isfinite(min_edge) ? min_edge : 0.0), 1e-6 * rho);
    // A nearly closed patch (a whole small body) has no meaningful mean normal: use its mean.
    const bool closed_like = normal_sum.norm() < 0.3 * area2;
    const Vec3 down = closed_like ? Vec3::Zero() : Vec3(-normal_sum.normalized());
    static constexpr std::array<double, 7> kDepths = {1.0, 2.0, 0.5, 4.0, 0.25, 8.0, 0.0};
    std::size_t best_fail = std::numeric_limits<std::size_t>::max();
    bool have_inside = false;
    Vec3 best = mean + rho * down;
    for (double depth : kDepths) {
      const Vec3 c = closed_like ? mean : Vec3(mean + depth * rho * down);
      const bool inside = bvh_.closest_point(c).signed_distance < 0.0;
      if (!inside) {
        if (closed_like) {
          break;
        }
        continue;
      }
      std::size_t fail = 0;
      for (std::uint32_t t : g.triangles) {
        const auto [a, b, cc] = mesh_.corners(t);
        fail += ((a + b + cc) / 3.0 - c).dot(mesh_.face_normal_area2(t)) > 0.0 ? 0 : 1;
      }
      if (fail == 0) {
        // Visibility only for centroids that pass the cheap test; one hidden vertex is enough.
        for (const auto* list : {&g.owned, &g.halo}) {
          for (std::size_t i = 0; i < list->size() && fail == 0; ++i) {
            fail += sees(c, mesh_.vertices[(*list)[i]], reach) ? 0 : 1;
          }
        }
      }
      if (!have_inside || fail < best_fail) {
        have_inside = true;
        best_fail = fail;
        best = c;
      }
      if (fail == 0 || closed_like) {
        break;
      }
    }
    g.centroid_m = closed_like && !have_inside ? mean : best;
    g.star_shaped = have_inside && best_fail == 0;
  }

  // True when the segment from `from` (inside the body) to the surface point `to` stays inside
  // the body until it is within `reach` of `to`: sphere tracing with the exact signed distance,
  // which never steps over a crossing. Grazing rays that make no progress count as hidden
  // (conservative: the group is then split or reported as not star-shaped).
  bool sees(const Vec3& from, const Vec3& to, double reach) const {
    const Vec3 delta = to - from;
    const double length = delta.norm();
    if (!(length > reach)) {
      return true;
    }
    const Vec3 dir = delta / length;
    QueryHint hint;
    double t = 0.0;
    for (int step = 0; step < 256; ++step) {
      const double remaining = length - t;
      if (remaining <= reach) {
        return true;
      }
      const double sd = bvh_.closest_point(from + t * dir, &hint).signed_distance;
      if (!(sd < 0.0) || -sd < 1e-3 * reach) {
        return false;
      }
      t += -sd;
    }
    return false;
  }

  void count_centroid(const KneeGroup& g) {
    Vec3 mean = Vec3::Zero();
    for (std::uint32_t v : g.owned) {
      mean += mesh_.vertices[v];
    }
    mean /= static_cast<double>(g.owned.size());
    if (bvh_.closest_point(mean).signed_distance >= 0.0) {
      ++pulled_inside_;
    }
    if (bvh_.closest_point(g.centroid_m).signed_distance >= 0.0) {
      ++outside_;
    }
  }

  const TriangleMesh& mesh_;
  const KneeGroupOptions& options_;
  Csr vt_;
  MeshBvh bvh_;
  std::vector<Vec3> normals_;
  std::vector<std::uint32_t> owner_;  // scratch labels
  double normal_scale_ = 0.0;
  std::size_t non_star_before_ = 0;
  std::size_t splits_ = 0;
  std::size_t pulled_inside_ = 0;
  std::size_t outside_ = 0;
};

}  // namespace

bool is_star_shaped_about(const TriangleMesh& mesh, const std::vector<std::uint32_t>& triangles,
                          const Vec3& centroid_m) {
  return std::all_of(triangles.begin(), triangles.end(), [&](std::uint32_t t) {
    const auto [a, b, c] = mesh.corners(t);
    return ((a + b + c) / 3.0 - centroid_m).dot(mesh.face_normal_area2(t)) > 0.0;
  });
}

KneeGrouping build_knee_groups(const TriangleMesh& mesh, const KneeGroupOptions& options) {
  GroupBuilder builder(mesh, options);
  return builder.build();
}

}  // namespace hapsim
