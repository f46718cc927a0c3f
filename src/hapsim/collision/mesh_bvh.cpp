#include "hapsim/collision/mesh_bvh.h"

#include "hapsim/core/stopwatch.h"

#include <emmintrin.h>  // SSE2 only: guaranteed on x86-64, no runtime dispatch needed

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace hapsim {
namespace {

constexpr float kFltInf = std::numeric_limits<float>::infinity();
// Child references: bit 31 set = leaf (bits 0-3 triangle count, bits 4-30 first slot), else the
// index of a 4-wide node.
constexpr std::uint32_t kLeafBit = 0x80000000u;
constexpr std::uint32_t kEmptyRef = 0xFFFFFFFFu;
constexpr int kMaxLeafTriangles = 15;
constexpr std::size_t kMaxLeafFirst = (std::size_t{1} << 27) - 1;
// Depth after which the builder stops trusting SAH and splits at the object median, so the
// traversal stack below stays bounded whatever the mesh.
constexpr int kSahMaxDepth = 40;
constexpr int kStackSize = 512;
// closest_point answers nothing for a coordinate beyond this (see there).
constexpr double kMaxQueryCoordinateM = 1e15;

// Conservative double -> float rounding: the float box always contains the double one.
float round_down(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) > x) {
    f = std::nextafter(f, -kFltInf);
  }
  return f;
}
float round_up(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) < x) {
    f = std::nextafter(f, kFltInf);
  }
  return f;
}

struct FBox {
  std::array<float, 3> lo{kFltInf, kFltInf, kFltInf};
  std::array<float, 3> hi{-kFltInf, -kFltInf, -kFltInf};

  void grow(const FBox& o) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], o.lo[k]);
      hi[k] = std::max(hi[k], o.hi[k]);
    }
  }
  void grow(const std::array<float, 3>& p) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  }
  [[nodiscard]] float half_area() const {
    const float dx = hi[0] - lo[0];
    const float dy = hi[1] - lo[1];
    const float dz = hi[2] - lo[2];
    return dx < 0.0f ? 0.0f : dx * dy + dy * dz + dz * dx;
  }
};

FBox triangle_box(const Vec3& a, const Vec3& b, const Vec3& c) {
  FBox box;
  for (int k = 0; k < 3; ++k) {
    box.lo[k] = round_down(std::min({a[k], b[k], c[k]}));
    box.hi[k] = round_up(std::max({a[k], b[k], c[k]}));
  }
  return box;
}

// Binary tree: the build's intermediate, collapsed into the 4-wide tree afterwards.
struct BinaryNode {
  FBox box;
  std::uint32_t left = 0;  // children, for inner nodes
  std::uint32_t right = 0;
  std::uint32_t first = 0;  // triangle slots, for leaves
  std::uint32_t count = 0;  // > 0: leaf
};

}  // namespace

// Four children per node, bounds as SoA float lanes so one SSE pass measures all four.
struct alignas(16) Node4 {
  float lo[3][4];
  float hi[3][4];
  std::uint32_t child[4];
};

struct LeafTriangle {
  std::uint32_t v[3];  // vertex indices copied from the mesh: one indirection fewer per test
  std::uint32_t id;    // triangle index in the mesh
};

struct MeshBvh::Impl {
  std::vector<Node4> nodes;
  std::vector<LeafTriangle> leaf_triangles;

  // ---- build ----
  struct Builder {
    Builder(const TriangleMesh& m, int leaf, const ProgressFn& fn)
        : mesh(m), max_leaf(leaf), progress(fn) {}
    const TriangleMesh& mesh;
    int max_leaf;
    const ProgressFn& progress;
    std::vector<FBox> boxes;
    std::vector<std::array<float, 3>> centroids;
    std::vector<std::uint32_t> order;
    std::vector<BinaryNode> binary;
    std::size_t placed = 0;
    std::size_t next_report = 0;

    std::uint32_t build(std::uint32_t first, std::uint32_t count, int depth);
    void leaf_done(std::uint32_t count);
  };

  void collapse(const std::vector<BinaryNode>& binary, std::uint32_t b, std::uint32_t node,
                std::size_t depth, BvhStats& stats);
  static std::uint32_t make_ref(const BinaryNode& n) { return kLeafBit | (n.first << 4) | n.count; }
  void refit(const TriangleMesh& mesh);
};

void MeshBvh::Impl::Builder::leaf_done(std::uint32_t count) {
  placed += count;
  if (progress && placed >= next_report) {
    report_progress(progress, "bvh build",
                    0.1 + 0.8 * static_cast<double>(placed) / static_cast<double>(order.size()));
    next_report = placed + order.size() / 50 + 1;
  }
}

// Binned SAH on the largest centroid axis (32 bins); object median past kSahMaxDepth or when
// the centroids coincide.
std::uint32_t MeshBvh::Impl::Builder::build(std::uint32_t first, std::uint32_t count, int depth) {
  const auto index = static_cast<std::uint32_t>(binary.size());
  binary.emplace_back();
  FBox box;
  FBox cbox;
  for (std::uint32_t i = first; i < first + count; ++i) {
    box.grow(boxes[order[i]]);
    cbox.grow(centroids[order[i]]);
  }
  binary[index].box = box;
  if (count <= static_cast<std::uint32_t>(max_leaf)) {
    binary[index].first = first;
    binary[index].count = count;
    leaf_done(count);
    return index;
  }
  int axis = 0;
  for (int k = 1; k < 3; ++k) {
    if (cbox.hi[k] - cbox.lo[k] > cbox.hi[axis] - cbox.lo[axis]) {
      axis = k;
    }
  }
  const float extent = cbox.hi[axis] - cbox.lo[axis];
  std::uint32_t mid = first + count / 2;
  bool split_done = false;
  if (depth < kSahMaxDepth && extent > 0.0f) {
    constexpr int kBins = 32;
    std::array<FBox, kBins> bin_box{};
    std::array<std::uint32_t, kBins> bin_count{};
    const float scale = kBins / extent * 0.99999f;
    const float lo = cbox.lo[axis];
    const auto bin_of = [&](std::uint32_t t) {
      return std::min(kBins - 1, static_cast<int>((centroids[t][axis] - lo) * scale));
    };
    for (std::uint32_t i = first; i < first + count; ++i) {
      const int b = bin_of(order[i]);
      ++bin_count[b];
      bin_box[b].grow(boxes[order[i]]);
    }
    // Sweep from the right for suffix areas, then from the left for the best split.
    std::array<float, kBins> right_cost{};
    FBox acc;
    std::uint32_t n_right = 0;
    for (int b = kBins - 1; b > 0; --b) {
      acc.grow(bin_box[b]);
      n_right += bin_count[b];
      right_cost[b] = acc.half_area() * static_cast<float>(n_right);
    }
    FBox left_acc;
    std::uint32_t n_left = 0;
    float best_cost = kFltInf;
    int best_bin = -1;
    for (int b = 0; b < kBins - 1; ++b) {
      left_acc.grow(bin_box[b]);
      n_left += bin_count[b];
      if (n_left == 0 || n_left == count) {
        continue;
      }
      const float cost = left_acc.half_area() * static_cast<float>(n_left) + right_cost[b + 1];
      if (cost < best_cost) {
        best_cost = cost;
        best_bin = b;
      }
    }
    if (best_bin >= 0) {
      const auto* split = std::partition(order.data() + first, order.data() + first + count,
                                         [&](std::uint32_t t) { return bin_of(t) <= best_bin; });
      mid = static_cast<std::uint32_t>(split - order.data());
      split_done = mid > first && mid < first + count;
    }
  }
  if (!split_done) {
    mid = first + count / 2;
    std::nth_element(
        order.begin() + first, order.begin() + mid, order.begin() + first + count,
        [&](std::uint32_t a, std::uint32_t b) { return centroids[a][axis] < centroids[b][axis]; });
  }
  const std::uint32_t left = build(first, mid - first, depth + 1);
  const std::uint32_t right = build(mid, first + count - mid, depth + 1);
  binary[index].left = left;
  binary[index].right = right;
  return index;
}

// Turns binary node `b` into 4-wide node `node`: opens the largest inner child until four.
void MeshBvh::Impl::collapse(const std::vector<BinaryNode>& binary, std::uint32_t b,
                             std::uint32_t node, std::size_t depth, BvhStats& stats) {
  stats.depth = std::max(stats.depth, depth);
  std::array<std::uint32_t, 4> kids{binary[b].left, binary[b].right, 0, 0};
  int n = 2;
  while (n < 4) {
    int open = -1;
    float best_area = -1.0f;
    for (int i = 0; i < n; ++i) {
      const BinaryNode& k = binary[kids[i]];
      if (k.count == 0 && k.box.half_area() > best_area) {
        best_area = k.box.half_area();
        open = i;
      }
    }
    if (open < 0) {
      break;
    }
    const BinaryNode& k = binary[kids[open]];
    kids[open] = k.left;
    kids[n++] = k.right;
  }
  for (int i = 0; i < 4; ++i) {
    Node4& nd = nodes[node];
    if (i >= n) {
      for (int k = 0; k < 3; ++k) {
        nd.lo[k][i] = kFltInf;
        nd.hi[k][i] = -kFltInf;
      }
      nd.child[i] = kEmptyRef;
      continue;
    }
    const BinaryNode& k = binary[kids[i]];
    for (int a = 0; a < 3; ++a) {
      nd.lo[a][i] = k.box.lo[a];
      nd.hi[a][i] = k.box.hi[a];
    }
    if (k.count > 0) {
      nd.child[i] = make_ref(k);
      ++stats.leaves;
    } else {
      const auto child = static_cast<std::uint32_t>(nodes.size());
      nodes.emplace_back();
      nodes[node].child[i] = child;  // `nd` may dangle after emplace_back
      collapse(binary, kids[i], child, depth + 1, stats);
    }
  }
}

// Bottom-up: nodes are stored parents-first, so a reverse sweep sees children before parents.
void MeshBvh::Impl::refit(const TriangleMesh& mesh) {
  for (std::size_t i = nodes.size(); i-- > 0;) {
    Node4& nd = nodes[i];
    for (int c = 0; c < 4; ++c) {
      const std::uint32_t ref = nd.child[c];
      if (ref == kEmptyRef) {
        continue;
      }
      FBox box;
      if (ref & kLeafBit) {
        const std::uint32_t first = (ref & ~kLeafBit) >> 4;
        const std::uint32_t count = ref & 15u;
        for (std::uint32_t k = first; k < first + count; ++k) {
          const LeafTriangle& t = leaf_triangles[k];
          box.grow(
              triangle_box(mesh.vertices[t.v[0]], mesh.vertices[t.v[1]], mesh.vertices[t.v[2]]));
        }
      } else {
        const Node4& ch = nodes[ref];
        for (int k = 0; k < 4; ++k) {
          for (int a = 0; a < 3; ++a) {
            box.lo[a] = std::min(box.lo[a], ch.lo[a][k]);
            box.hi[a] = std::max(box.hi[a], ch.hi[a][k]);
          }
        }
      }
      for (int a = 0; a < 3; ++a) {
        nd.lo[a][c] = box.lo[a];
        nd.hi[a][c] = box.hi[a];
      }
    }
  }
}

MeshBvh::MeshBvh(const TriangleMesh& mesh, BvhBuildOptions options)
    : mesh_(&mesh), impl_(new Impl) {
  const Stopwatch watch;
  const std::size_t n = mesh.triangles.size();
  if (n > kMaxLeafFirst) {
    delete impl_;
    throw std::length_error("MeshBvh: more than 2^27 triangles");
  }
  report_progress(options.progress, "bvh build", 0.0);
  sign_ = SignedSurface(mesh);
  report_progress(options.progress, "bvh build", 0.1);
  if (n > 0) {
    Impl::Builder builder(mesh, std::clamp(options.max_leaf_triangles, 1, kMaxLeafTriangles),
                          options.progress);
    builder.boxes.resize(n);
    builder.centroids.resize(n);
    builder.order.resize(n);
    for (std::size_t t = 0; t < n; ++t) {
      const auto [a, b, c] = mesh.corners(t);
      builder.boxes[t] = triangle_box(a, b, c);
      const Vec3 centroid = (a + b + c) / 3.0;
      builder.centroids[t] = {static_cast<float>(centroid.x()), static_cast<float>(centroid.y()),
                              static_cast<float>(centroid.z())};
      builder.order[t] = static_cast<std::uint32_t>(t);
    }
    builder.binary.reserve(2 * n / static_cast<std::size_t>(builder.max_leaf) + 2);
    builder.build(0, static_cast<std::uint32_t>(n), 0);

    impl_->leaf_triangles.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const TriangleIndices& tri = mesh.triangles[builder.order[i]];
      impl_->leaf_triangles[i] = {{tri[0], tri[1], tri[2]}, builder.order[i]};
    }
    impl_->nodes.reserve(builder.binary.size() / 2 + 1);
    impl_->nodes.emplace_back();
    const BinaryNode& root = builder.binary[0];
    if (root.count > 0) {
      // A tiny mesh: one node holding one leaf.
      Node4& nd = impl_->nodes[0];
      for (int i = 0; i < 4; ++i) {
        for (int a = 0; a < 3; ++a) {
          nd.lo[a][i] = i == 0 ? root.box.lo[a] : kFltInf;
          nd.hi[a][i] = i == 0 ? root.box.hi[a] : -kFltInf;
        }
        nd.child[i] = i == 0 ? Impl::make_ref(root) : kEmptyRef;
      }
      stats_.leaves = 1;
      stats_.depth = 1;
    } else {
      impl_->collapse(builder.binary, 0, 0, 1, stats_);
    }
    impl_->nodes.shrink_to_fit();
  }
  stats_.nodes = impl_->nodes.size();
  stats_.memory_bytes = memory_bytes();
  stats_.build_ms = watch.elapsed_ms();
  report_progress(options.progress, "bvh build", 1.0);
}

MeshBvh::~MeshBvh() {
  delete impl_;
}

void MeshBvh::refit() {
  const Stopwatch watch;
  impl_->refit(*mesh_);
  sign_.update_normals(*mesh_);
}

std::size_t MeshBvh::memory_bytes() const {
  return sizeof(MeshBvh) + sizeof(Impl) + impl_->nodes.capacity() * sizeof(Node4) +
         impl_->leaf_triangles.capacity() * sizeof(LeafTriangle) + sign_.memory_bytes();
}

namespace {

struct Best {
  double d2 = kInf;
  std::uint32_t triangle = kNoTriangle;
  TriangleClosest closest{Vec3::Zero(), kInf, TriangleFeature::kFace};
};

struct StackEntry {
  std::uint32_t ref;
  float d2;
};

}  // namespace

// The traversal shared by every query: nearest-first, stack-based, pruning 4 float boxes at a
// time against the best exact squared distance so far. `best` holds the starting bound (hint or
// contact radius) and receives the answer. haptic path: no allocation.
template <bool kCount>
static void traverse(const std::vector<Node4>& nodes, const std::vector<LeafTriangle>& leaves,
                     const TriangleMesh& mesh, const Vec3& p, Best& best, QueryCounters* counters) {
  if (nodes.empty()) {
    return;
  }
  const float pxf = static_cast<float>(p.x());
  const float pyf = static_cast<float>(p.y());
  const float pzf = static_cast<float>(p.z());
  // |p_float - p|: the float box distances are measured from p_float, so the bound is widened
  // by this much (plus float rounding) to stay a true lower bound for p.
  const double shift =
      (Vec3(pxf, pyf, pzf) - p).norm() * (1.0 + 1e-9) + std::numeric_limits<double>::denorm_min();
  const auto threshold = [shift](double d2) {
    if (!(d2 < kInf)) {
      return kFltInf;
    }
    const double r = std::sqrt(d2) + shift;
    return round_up(r * r * (1.0 + 1e-6));
  };
  float thr = threshold(best.d2);
  const __m128 px = _mm_set1_ps(pxf);
  const __m128 py = _mm_set1_ps(pyf);
  const __m128 pz = _mm_set1_ps(pzf);
  const __m128 zero = _mm_setzero_ps();
  const Vec3* const verts = mesh.vertices.data();

  StackEntry stack[kStackSize];
  int sp = 0;
  std::uint32_t ref = 0;
  for (;;) {
    if (!(ref & kLeafBit)) {
      const Node4& nd = nodes[ref];
      if constexpr (kCount) {
        ++counters->nodes_visited;
      }
      const __m128 dx = _mm_max_ps(
          _mm_max_ps(_mm_sub_ps(_mm_load_ps(nd.lo[0]), px), _mm_sub_ps(px, _mm_load_ps(nd.hi[0]))),
          zero);
      const __m128 dy = _mm_max_ps(
          _mm_max_ps(_mm_sub_ps(_mm_load_ps(nd.lo[1]), py), _mm_sub_ps(py, _mm_load_ps(nd.hi[1]))),
          zero);
      const __m128 dz = _mm_max_ps(
          _mm_max_ps(_mm_sub_ps(_mm_load_ps(nd.lo[2]), pz), _mm_sub_ps(pz, _mm_load_ps(nd.hi[2]))),
          zero);
      const __m128 d2v =
          _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
      int mask = _mm_movemask_ps(_mm_cmplt_ps(d2v, _mm_set1_ps(thr)));
      if (mask != 0) {
        alignas(16) float d2s[4];
        _mm_store_ps(d2s, d2v);
        // Gather the hits, sort by distance (at most 4: insertion sort), push all but the
        // nearest farthest-first and descend into the nearest.
        StackEntry hit[4];
        int n = 0;
        while (mask != 0) {
          const int i = __builtin_ctz(static_cast<unsigned>(mask));
          mask &= mask - 1;
          StackEntry e{nd.child[i], d2s[i]};
          int j = n++;
          while (j > 0 && hit[j - 1].d2 > e.d2) {
            hit[j] = hit[j - 1];
            --j;
          }
          hit[j] = e;
        }
        for (int i = n - 1; i > 0; --i) {
          stack[sp++] = hit[i];
        }
        ref = hit[0].ref;
        continue;
      }
    } else {
      const std::uint32_t first = (ref & ~kLeafBit) >> 4;
      const std::uint32_t count = ref & 15u;
      for (std::uint32_t k = first; k < first + count; ++k) {
        const LeafTriangle& t = leaves[k];
        if constexpr (kCount) {
          ++counters->triangles_tested;
        }
        const TriangleClosest c =
            closest_point_on_triangle(p, verts[t.v[0]], verts[t.v[1]], verts[t.v[2]]);
        if (c.distance_sq < best.d2) {
          best.d2 = c.distance_sq;
          best.triangle = t.id;
          best.closest = c;
          thr = threshold(best.d2);
        }
      }
    }
    // Pop the next entry that the (possibly tightened) bound has not pruned.
    for (;;) {
      if (sp == 0) {
        return;
      }
      const StackEntry& e = stack[--sp];
      if (e.d2 < thr) {
        ref = e.ref;
        break;
      }
    }
  }
}

namespace {

// Exact distance to last cycle's triangle: an upper bound that prunes almost everything.
void seed_from_hint(const TriangleMesh& mesh, const Vec3& p, const QueryHint* hint, Best& best) {
  if (hint == nullptr || hint->triangle >= mesh.triangles.size()) {
    return;
  }
  const auto [a, b, c] = mesh.corners(hint->triangle);
  const TriangleClosest closest = closest_point_on_triangle(p, a, b, c);
  if (closest.distance_sq < best.d2) {
    best.d2 = closest.distance_sq;
    best.triangle = hint->triangle;
    best.closest = closest;
  }
}

}  // namespace

SurfacePoint MeshBvh::closest_point(const Vec3& p, QueryHint* hint) const {
  return closest_point_counted(p, hint, nullptr);
}

// haptic path: no allocation.
SurfacePoint MeshBvh::closest_point_counted(const Vec3& p, QueryHint* hint,
                                            QueryCounters* counters) const {
  Best best;
  // No point, no closest point: a NaN query once crashed the Python interpreter, one at 1e308 m
  // the traversal (float boxes overflow there). Past 1e15 m a double cannot tell a millimetre
  // from nothing, so the near face of a metre-sized body and its far one tie, and the sign
  // came out "inside": no answer is the honest one.
  if (!p.allFinite() || p.cwiseAbs().maxCoeff() > kMaxQueryCoordinateM) {
    return {};
  }
  seed_from_hint(*mesh_, p, hint, best);
  if (counters != nullptr) {
    traverse<true>(impl_->nodes, impl_->leaf_triangles, *mesh_, p, best, counters);
  } else {
    traverse<false>(impl_->nodes, impl_->leaf_triangles, *mesh_, p, best, nullptr);
  }
  if (best.triangle == kNoTriangle) {
    // Only if float box distances overflowed: scan everything.
    for (std::uint32_t t = 0; t < mesh_->triangles.size(); ++t) {
      const auto [a, b, c] = mesh_->corners(t);
      const TriangleClosest closest = closest_point_on_triangle(p, a, b, c);
      if (closest.distance_sq < best.d2) {
        best = {closest.distance_sq, t, closest};
      }
    }
  }
  if (best.triangle == kNoTriangle) {
    return {};
  }
  if (hint != nullptr) {
    hint->triangle = best.triangle;
  }
  return sign_.resolve(*mesh_, p, best.triangle, best.closest);
}

// haptic path: no allocation.
bool MeshBvh::contact_within(const Vec3& p, double radius, SurfacePoint* out,
                             QueryHint* hint) const {
  return contact_within_counted(p, radius, out, hint, nullptr);
}

// haptic path: no allocation.
bool MeshBvh::contact_within_counted(const Vec3& p, double radius, SurfacePoint* out,
                                     QueryHint* hint, QueryCounters* counters) const {
  if (!(radius >= 0.0)) {
    return false;
  }
  // r² nudged up two ulps so rounding in r·r never drops a triangle at exactly `radius`; the
  // final decision is made on the distance itself.
  Best best;
  best.d2 = std::nextafter(std::nextafter(radius * radius, kInf), kInf);
  seed_from_hint(*mesh_, p, hint, best);
  if (counters != nullptr) {
    traverse<true>(impl_->nodes, impl_->leaf_triangles, *mesh_, p, best, counters);
  } else {
    traverse<false>(impl_->nodes, impl_->leaf_triangles, *mesh_, p, best, nullptr);
  }
  if (best.triangle == kNoTriangle || !(std::sqrt(best.d2) <= radius)) {
    return false;
  }
  if (hint != nullptr) {
    hint->triangle = best.triangle;
  }
  if (out != nullptr) {
    *out = sign_.resolve(*mesh_, p, best.triangle, best.closest);
  }
  return true;
}

}  // namespace hapsim
