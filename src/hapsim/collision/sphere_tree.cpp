#include "hapsim/collision/sphere_tree.h"

#include "hapsim/collision/minimal_sphere.h"
#include "hapsim/collision/point_triangle.h"
#include "hapsim/core/stopwatch.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

namespace hapsim {
namespace {

constexpr int kMaxBranching = 32;
constexpr int kMaxLeafTriangles = 64;
// Fixed traversal stacks (haptic path: no allocation). The build checks the point-query bound
// (Σ over a root-leaf path of (children − 1), + 1); the pair traversal's bound is checked per call.
constexpr std::size_t kMaxStack = 512;
constexpr std::size_t kMaxPairStack = 4096;

// Children of node n are nodes [first_child, first_child + child_count); a leaf has
// child_count == 0. Every node covers the triangle slots [slot_begin, slot_end), so a leaf's
// triangles and a subtree's triangles are contiguous in slot order.
struct Node {
  std::uint32_t first_child = 0;
  std::uint32_t child_count = 0;
  std::uint32_t slot_begin = 0;
  std::uint32_t slot_end = 0;
};

struct StackEntry {
  std::uint32_t node;
  double lower_bound_m;
};

// Best triangle so far; `closest` is its exact closest point.
struct Best {
  double distance_sq = kInf;
  std::uint32_t triangle = kNoTriangle;
  TriangleClosest closest{};
};

}  // namespace

struct SphereTree::Impl {
  std::vector<Node> nodes;
  // Node spheres, structure-of-arrays so a node's contiguous children load as packed lanes.
  std::vector<double> cx, cy, cz, radius;
  std::vector<std::uint16_t> level;
  std::vector<std::uint32_t> identity;   // identity[i] == i: backs node_children() spans
  std::vector<std::uint32_t> leaf_node;  // leaf -> node
  std::vector<std::uint32_t> node_leaf;  // node -> leaf (kNoTriangle for inner nodes)
  std::vector<std::uint32_t> triangle_of_slot;
  // Corners of the triangle in each slot (3 per slot), copied in leaf order for locality.
  std::vector<Vec3> corners;
  // Minimal sphere of each slot's triangle (SoA): a two-flop lower bound that skips most exact
  // triangle tests in a leaf whose sphere was only just within reach.
  std::vector<double> tx, ty, tz, tr;
  std::size_t depth = 0;
  std::size_t point_stack_bound = 0;
  std::size_t max_children = 1;  // the most children of any node (tree-vs-tree stack bound)

  void build_topology(const TriangleMesh& mesh, int branching, int max_leaf,
                      const ProgressFn& progress);
  void copy_corners(const TriangleMesh& mesh);
  void compute_spheres();

  [[nodiscard]] Sphere sphere(std::size_t n) const {
    return {Vec3(cx[n], cy[n], cz[n]), radius[n]};
  }
  void set_sphere(std::size_t n, const Sphere& s) {
    cx[n] = s.center.x();
    cy[n] = s.center.y();
    cz[n] = s.center.z();
    radius[n] = s.radius;
  }

  template <bool kCount>
  void search(const TriangleMesh& mesh, const Vec3& p, double limit_distance_sq,
              std::uint32_t hint_triangle, Best& best, SphereQueryCounters* counters) const;
};

namespace {

// Splits order[begin, end) into `groups` parts of proportional size, each cut at the median
// centroid along the widest axis of the part being cut (recursive bisection: for 4 children
// the cut directions adapt to each half, unlike 4 slabs along one axis). Appends the part ends.
void split_groups(std::vector<std::uint32_t>& order, const std::vector<Vec3>& centroids,
                  std::size_t begin, std::size_t end, int groups,
                  std::vector<std::size_t>& part_ends) {
  if (groups <= 1) {
    part_ends.push_back(end);
    return;
  }
  const int left_groups = groups / 2;
  const std::size_t count = end - begin;
  const std::size_t mid = begin + (count * static_cast<std::size_t>(left_groups) +
                                   static_cast<std::size_t>(groups) / 2) /
                                      static_cast<std::size_t>(groups);
  Box3 box;
  for (std::size_t i = begin; i < end; ++i) {
    box.extend(centroids[order[i]]);
  }
  Eigen::Index axis = 0;
  box.sizes().maxCoeff(&axis);
  std::nth_element(
      order.begin() + static_cast<std::ptrdiff_t>(begin),
      order.begin() + static_cast<std::ptrdiff_t>(mid),
      order.begin() + static_cast<std::ptrdiff_t>(end),
      [&](std::uint32_t a, std::uint32_t b) { return centroids[a][axis] < centroids[b][axis]; });
  split_groups(order, centroids, begin, mid, left_groups, part_ends);
  split_groups(order, centroids, mid, end, groups - left_groups, part_ends);
}

}  // namespace

void SphereTree::Impl::build_topology(const TriangleMesh& mesh, int branching, int max_leaf,
                                      const ProgressFn& progress) {
  const std::size_t n = mesh.triangle_count();
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0U);
  std::vector<Vec3> centroids(n);
  for (std::size_t t = 0; t < n; ++t) {
    const auto c = mesh.corners(t);
    centroids[t] = (c[0] + c[1] + c[2]) / 3.0;
  }
  nodes.clear();
  level.clear();
  nodes.push_back({0, 0, 0, static_cast<std::uint32_t>(n)});
  level.push_back(0);
  std::vector<std::uint32_t> pending{0};
  std::vector<std::size_t> part_ends;
  std::size_t placed = 0;
  std::size_t next_report = n / 20;
  while (!pending.empty()) {
    const std::uint32_t node = pending.back();
    pending.pop_back();
    const std::size_t begin = nodes[node].slot_begin;
    const std::size_t end = nodes[node].slot_end;
    const std::size_t count = end - begin;
    if (count <= static_cast<std::size_t>(max_leaf)) {
      placed += count;
      if (placed >= next_report) {
        report_progress(progress, "sphere tree: build",
                        0.8 * static_cast<double>(placed) / static_cast<double>(n));
        next_report += std::max<std::size_t>(n / 20, 1);
      }
      continue;
    }
    // As few children as fill the leaves, capped at the branching factor.
    const std::size_t wanted =
        (count + static_cast<std::size_t>(max_leaf) - 1) / static_cast<std::size_t>(max_leaf);
    const int groups =
        static_cast<int>(std::clamp<std::size_t>(wanted, 2, static_cast<std::size_t>(branching)));
    part_ends.clear();
    split_groups(order, centroids, begin, end, groups, part_ends);
    const auto first = static_cast<std::uint32_t>(nodes.size());
    nodes[node].first_child = first;
    nodes[node].child_count = static_cast<std::uint32_t>(groups);
    std::size_t part_begin = begin;
    const auto child_level = static_cast<std::uint16_t>(level[node] + 1);
    for (std::size_t part_end : part_ends) {
      nodes.push_back(
          {0, 0, static_cast<std::uint32_t>(part_begin), static_cast<std::uint32_t>(part_end)});
      level.push_back(child_level);
      part_begin = part_end;
    }
    // Depth-first (first child on top): a subtree's nodes end up close together in memory.
    for (int g = groups - 1; g >= 0; --g) {
      pending.push_back(first + static_cast<std::uint32_t>(g));
    }
  }

  triangle_of_slot = std::move(order);
  const std::size_t node_count = nodes.size();
  identity.resize(node_count);
  std::iota(identity.begin(), identity.end(), 0U);
  node_leaf.assign(node_count, kNoTriangle);
  leaf_node.clear();
  // Leaves numbered in slot order (leaf i's triangles precede leaf i+1's).
  std::vector<std::uint32_t> leaves;
  for (std::uint32_t i = 0; i < node_count; ++i) {
    if (nodes[i].child_count == 0) {
      leaves.push_back(i);
    }
  }
  std::sort(leaves.begin(), leaves.end(), [&](std::uint32_t a, std::uint32_t b) {
    return nodes[a].slot_begin < nodes[b].slot_begin;
  });
  for (std::uint32_t leaf = 0; leaf < leaves.size(); ++leaf) {
    node_leaf[leaves[leaf]] = leaf;
  }
  leaf_node = std::move(leaves);

  // Depth and the point-query stack bound, top-down (children always follow their parent).
  std::vector<std::size_t> stack_need(node_count, 1);
  depth = 0;
  point_stack_bound = 1;
  max_children = 1;
  for (std::size_t i = 0; i < node_count; ++i) {
    depth = std::max<std::size_t>(depth, level[i] + 1U);
    point_stack_bound = std::max(point_stack_bound, stack_need[i]);
    const Node& nd = nodes[i];
    max_children = std::max<std::size_t>(max_children, nd.child_count);
    for (std::uint32_t c = 0; c < nd.child_count; ++c) {
      stack_need[nd.first_child + c] = stack_need[i] + nd.child_count - 1;
    }
  }
  if (point_stack_bound > kMaxStack) {
    throw std::invalid_argument("SphereTree: tree too deep for the fixed query stack (" +
                                std::to_string(point_stack_bound) + " > " +
                                std::to_string(kMaxStack) + ")");
  }
  cx.assign(node_count, 0.0);
  cy.assign(node_count, 0.0);
  cz.assign(node_count, 0.0);
  radius.assign(node_count, 0.0);
}

void SphereTree::Impl::copy_corners(const TriangleMesh& mesh) {
  const std::size_t n = triangle_of_slot.size();
  corners.resize(n * 3);
  tx.resize(n);
  ty.resize(n);
  tz.resize(n);
  tr.resize(n);
  for (std::size_t s = 0; s < n; ++s) {
    const TriangleIndices& tri = mesh.triangles[triangle_of_slot[s]];
    for (std::size_t k = 0; k < 3; ++k) {
      corners[3 * s + k] = mesh.vertices[tri[k]];
    }
    const Sphere ts = triangle_sphere(corners[3 * s], corners[3 * s + 1], corners[3 * s + 2]);
    tx[s] = ts.center.x();
    ty[s] = ts.center.y();
    tz[s] = ts.center.z();
    tr[s] = ts.radius;
  }
}

// Bottom-up (children have larger indices than their parent): a leaf gets the minimal sphere
// of its corners, a parent the smallest sphere around its children's spheres, so every child
// sphere is inside its parent by construction (seed 000 §3.1), before and after refit. O(n).
void SphereTree::Impl::compute_spheres() {
  std::array<Vec3, 3 * kMaxLeafTriangles> points;
  std::array<Sphere, kMaxBranching> children;
  for (std::size_t i = nodes.size(); i-- > 0;) {
    const Node& nd = nodes[i];
    if (nd.child_count == 0) {
      const std::size_t count = 3 * (nd.slot_end - nd.slot_begin);
      std::copy_n(corners.begin() + static_cast<std::ptrdiff_t>(3 * nd.slot_begin), count,
                  points.begin());
      set_sphere(i, minimal_sphere_inplace(std::span<Vec3>(points.data(), count), false));
    } else {
      for (std::uint32_t c = 0; c < nd.child_count; ++c) {
        children[c] = sphere(nd.first_child + c);
      }
      set_sphere(i, enclosing_sphere_inplace(std::span<Sphere>(children.data(), nd.child_count)));
    }
  }
}

// Ordered depth-first search with pruning by the current best distance. The hint triangle
// (last cycle's answer) gives an exact upper bound before the first sphere is looked at, so
// for a probe that moved a little almost every subtree is pruned at once. Nodes whose lower
// bound max(0, |p − c| − R) exceeds min(best, limit) are skipped; children are pushed
// farthest-first so the nearest is explored next. haptic path: no allocation.
template <bool kCount>
void SphereTree::Impl::search(const TriangleMesh& mesh, const Vec3& p, double limit_distance_sq,
                              std::uint32_t hint_triangle, Best& best,
                              SphereQueryCounters* counters) const {
  if (nodes.empty()) {
    return;
  }
  if (hint_triangle < mesh.triangle_count()) {
    const TriangleIndices& tri = mesh.triangles[hint_triangle];
    const TriangleClosest tc = closest_point_on_triangle(
        p, mesh.vertices[tri[0]], mesh.vertices[tri[1]], mesh.vertices[tri[2]]);
    if constexpr (kCount) {
      ++counters->triangles_tested;
    }
    if (tc.distance_sq <= limit_distance_sq) {
      best = {tc.distance_sq, hint_triangle, tc};
    }
  }
  const double px = p.x();
  const double py = p.y();
  const double pz = p.z();
  double bound_m = std::sqrt(std::min(best.distance_sq, limit_distance_sq));

  std::array<StackEntry, kMaxStack> stack;
  std::size_t top = 0;
  {
    const double dx = cx[0] - px;
    const double dy = cy[0] - py;
    const double dz = cz[0] - pz;
    stack[top++] = {0, std::sqrt(dx * dx + dy * dy + dz * dz) - radius[0]};
    if constexpr (kCount) {
      ++counters->sphere_tests;
    }
  }
  std::array<double, kMaxBranching> child_lb;
  std::array<std::uint32_t, kMaxBranching> child_order;
  while (top > 0) {
    const StackEntry entry = stack[--top];
    if (entry.lower_bound_m > bound_m) {
      continue;  // the best improved since this entry was pushed
    }
    const Node& nd = nodes[entry.node];
    if constexpr (kCount) {
      ++counters->nodes_visited;
    }
    if (nd.child_count == 0) {
      for (std::uint32_t s = nd.slot_begin; s < nd.slot_end; ++s) {
        const double dx = tx[s] - px;
        const double dy = ty[s] - py;
        const double dz = tz[s] - pz;
        const double reach = bound_m + tr[s];
        if (dx * dx + dy * dy + dz * dz > reach * reach) {
          continue;  // the triangle's own sphere is out of reach
        }
        const TriangleClosest tc =
            closest_point_on_triangle(p, corners[3 * s], corners[3 * s + 1], corners[3 * s + 2]);
        if constexpr (kCount) {
          ++counters->triangles_tested;
        }
        if (tc.distance_sq < best.distance_sq && tc.distance_sq <= limit_distance_sq) {
          best = {tc.distance_sq, triangle_of_slot[s], tc};
          bound_m = std::sqrt(tc.distance_sq);
        }
      }
      continue;
    }
    const std::uint32_t first = nd.first_child;
    const std::uint32_t count = nd.child_count;
    for (std::uint32_t c = 0; c < count; ++c) {
      const double dx = cx[first + c] - px;
      const double dy = cy[first + c] - py;
      const double dz = cz[first + c] - pz;
      child_lb[c] = std::sqrt(dx * dx + dy * dy + dz * dz) - radius[first + c];
    }
    if constexpr (kCount) {
      counters->sphere_tests += count;
    }
    // Keep the children that can still win, sorted by lower bound descending (insertion sort:
    // at most `branching` items), so the nearest ends on top of the stack.
    std::uint32_t kept = 0;
    for (std::uint32_t c = 0; c < count; ++c) {
      const double lb = child_lb[c];
      if (lb > bound_m) {
        continue;
      }
      std::uint32_t k = kept++;
      while (k > 0 && child_lb[child_order[k - 1]] < lb) {
        child_order[k] = child_order[k - 1];
        --k;
      }
      child_order[k] = c;
    }
    for (std::uint32_t k = 0; k < kept; ++k) {
      const std::uint32_t c = child_order[k];
      stack[top++] = {first + c, child_lb[c]};
    }
  }
}

SphereTree::SphereTree(const TriangleMesh& mesh, SphereTreeOptions options)
    : mesh_(&mesh), impl_(new Impl) {
  const int branching = std::clamp(options.branching, 2, kMaxBranching);
  const int max_leaf = std::clamp(options.max_leaf_triangles, 1, kMaxLeafTriangles);
  const Stopwatch watch;
  sign_ = SignedSurface(mesh);
  if (!mesh.empty()) {
    impl_->build_topology(mesh, branching, max_leaf, options.progress);
    impl_->copy_corners(mesh);
    impl_->compute_spheres();
  }
  stats_.build_ms = watch.elapsed_ms();
  stats_.nodes = impl_->nodes.size();
  stats_.leaves = impl_->leaf_node.size();
  stats_.depth = impl_->depth;
  stats_.memory_bytes = memory_bytes();
  report_progress(options.progress, "sphere tree: tightness", 0.8);
  update_tightness();
  report_progress(options.progress, "sphere tree: done", 1.0);
}

SphereTree::~SphereTree() {
  delete impl_;
}

void SphereTree::update_tightness() {
  const Impl& im = *impl_;
  double leaf_sum = 0.0;
  double inner_sum = 0.0;
  std::size_t inner_count = 0;
  std::vector<Vec3> scratch;
  for (std::size_t i = 0; i < im.nodes.size(); ++i) {
    const Node& nd = im.nodes[i];
    scratch.assign(im.corners.begin() + static_cast<std::ptrdiff_t>(3 * nd.slot_begin),
                   im.corners.begin() + static_cast<std::ptrdiff_t>(3 * nd.slot_end));
    const double minimal = minimal_sphere_inplace(scratch, true).radius;
    // A leaf of one degenerate point-triangle has a zero minimal sphere: count it as tight.
    const double ratio = minimal > 0.0 ? im.radius[i] / minimal : 1.0;
    if (nd.child_count == 0) {
      leaf_sum += ratio;
    } else {
      inner_sum += ratio;
      ++inner_count;
    }
  }
  stats_.leaf_tightness =
      im.leaf_node.empty() ? 0.0 : leaf_sum / static_cast<double>(im.leaf_node.size());
  stats_.inner_tightness = inner_count == 0 ? 1.0 : inner_sum / static_cast<double>(inner_count);
}

SurfacePoint SphereTree::closest_point(const Vec3& p, QueryHint* hint) const {
  Best best;
  impl_->search<false>(*mesh_, p, kInf, hint != nullptr ? hint->triangle : kNoTriangle, best,
                       nullptr);
  if (best.triangle == kNoTriangle) {
    return {};
  }
  if (hint != nullptr) {
    hint->triangle = best.triangle;
  }
  return sign_.resolve(*mesh_, p, best.triangle, best.closest);
}

SurfacePoint SphereTree::closest_point_counted(const Vec3& p, QueryHint* hint,
                                               SphereQueryCounters* counters) const {
  SphereQueryCounters local;
  SphereQueryCounters* c = counters != nullptr ? counters : &local;
  Best best;
  impl_->search<true>(*mesh_, p, kInf, hint != nullptr ? hint->triangle : kNoTriangle, best, c);
  if (best.triangle == kNoTriangle) {
    return {};
  }
  if (hint != nullptr) {
    hint->triangle = best.triangle;
  }
  return sign_.resolve(*mesh_, p, best.triangle, best.closest);
}

bool SphereTree::contact_within(const Vec3& p, double radius, SurfacePoint* out,
                                QueryHint* hint) const {
  return contact_within_counted(p, radius, out, hint, nullptr);
}

bool SphereTree::contact_within_counted(const Vec3& p, double radius, SurfacePoint* out,
                                        QueryHint* hint, SphereQueryCounters* counters) const {
  if (!(radius >= 0.0)) {
    return false;
  }
  Best best;
  const std::uint32_t hint_triangle = hint != nullptr ? hint->triangle : kNoTriangle;
  if (counters != nullptr) {
    impl_->search<true>(*mesh_, p, radius * radius, hint_triangle, best, counters);
  } else {
    impl_->search<false>(*mesh_, p, radius * radius, hint_triangle, best, nullptr);
  }
  if (best.triangle == kNoTriangle) {
    return false;  // hint kept: still last cycle's best guess
  }
  if (hint != nullptr) {
    hint->triangle = best.triangle;
  }
  if (out != nullptr) {
    *out = sign_.resolve(*mesh_, p, best.triangle, best.closest);
  }
  return true;
}

void SphereTree::refit() {
  sign_.update_normals(*mesh_);
  if (impl_->nodes.empty()) {
    return;
  }
  impl_->copy_corners(*mesh_);
  impl_->compute_spheres();
}

// Simultaneous descent: a pair is expanded only when its two spheres overlap; the larger sphere
// (or the non-leaf) is split, which keeps the pairs' sizes balanced. haptic path: no allocation
// as long as `out` has capacity.
bool SphereTree::overlapping_leaves(const SphereTree& other, const Iso3& X_this_other,
                                    std::vector<LeafPair>& out, TreeTraversalCounters* counters,
                                    double margin_m, std::size_t max_pairs) const {
  const Impl& a = *impl_;
  const Impl& b = *other.impl_;
  if (a.nodes.empty() || b.nodes.empty()) {
    return true;
  }
  // Each step pops one pair and pushes at most `children` pairs, along at most
  // depth_a + depth_b steps (both known since the build: this runs every haptic step).
  const std::size_t max_children = std::max(a.max_children, b.max_children);
  if ((a.depth + b.depth) * (max_children - 1) + 1 > kMaxPairStack) {
    throw std::length_error("SphereTree::overlapping_leaves: trees too deep for the pair stack");
  }
  const Mat3 rotation = X_this_other.linear();
  const Vec3 translation = X_this_other.translation();
  const auto center_b = [&](std::uint32_t n) {
    return Vec3(rotation * Vec3(b.cx[n], b.cy[n], b.cz[n]) + translation);
  };
  std::size_t tests = 0;
  const auto overlap = [&](std::uint32_t na, const Vec3& cb, double rb) {
    ++tests;
    const double dx = a.cx[na] - cb.x();
    const double dy = a.cy[na] - cb.y();
    const double dz = a.cz[na] - cb.z();
    const double reach = a.radius[na] + rb + margin_m;
    return dx * dx + dy * dy + dz * dz <= reach * reach;
  };

  struct Pair {
    std::uint32_t a;
    std::uint32_t b;
  };
  std::array<Pair, kMaxPairStack> stack;
  std::size_t top = 0;
  bool complete = true;
  if (overlap(0, center_b(0), b.radius[0])) {
    stack[top++] = {0, 0};
  }
  while (top > 0) {
    const Pair pair = stack[--top];
    const Node& na = a.nodes[pair.a];
    const Node& nb = b.nodes[pair.b];
    const bool leaf_a = na.child_count == 0;
    const bool leaf_b = nb.child_count == 0;
    if (leaf_a && leaf_b) {
      if (out.size() >= max_pairs) {
        complete = false;
        break;
      }
      out.push_back({a.node_leaf[pair.a], b.node_leaf[pair.b]});
      continue;
    }
    if (leaf_b || (!leaf_a && a.radius[pair.a] >= b.radius[pair.b])) {
      const Vec3 cb = center_b(pair.b);
      const double rb = b.radius[pair.b];
      for (std::uint32_t c = na.child_count; c-- > 0;) {
        if (overlap(na.first_child + c, cb, rb)) {
          stack[top++] = {na.first_child + c, pair.b};
        }
      }
    } else {
      for (std::uint32_t c = nb.child_count; c-- > 0;) {
        const std::uint32_t child = nb.first_child + c;
        if (overlap(pair.a, center_b(child), b.radius[child])) {
          stack[top++] = {pair.a, child};
        }
      }
    }
  }
  if (counters != nullptr) {
    counters->sphere_tests += tests;
  }
  return complete;
}

std::size_t SphereTree::memory_bytes() const {
  const Impl& im = *impl_;
  const std::size_t n = im.nodes.size();
  return sizeof(Impl) +
         n * (sizeof(Node) + 4 * sizeof(double) + sizeof(std::uint16_t) +
              2 * sizeof(std::uint32_t)) +
         im.leaf_node.size() * sizeof(std::uint32_t) +
         im.triangle_of_slot.size() * (sizeof(std::uint32_t) + 4 * sizeof(double)) +
         im.corners.size() * sizeof(Vec3) + sign_.memory_bytes();
}

std::size_t SphereTree::node_count() const {
  return impl_->nodes.size();
}

Sphere SphereTree::node_sphere(std::size_t node) const {
  return impl_->sphere(node);
}

std::size_t SphereTree::node_level(std::size_t node) const {
  return impl_->level[node];
}

std::span<const std::uint32_t> SphereTree::node_children(std::size_t node) const {
  const Node& nd = impl_->nodes[node];
  return {impl_->identity.data() + nd.first_child, nd.child_count};
}

std::size_t SphereTree::leaf_count() const {
  return impl_->leaf_node.size();
}

std::size_t SphereTree::leaf_node(std::size_t leaf) const {
  return impl_->leaf_node[leaf];
}

std::span<const std::uint32_t> SphereTree::leaf_triangles(std::size_t leaf) const {
  const Node& nd = impl_->nodes[impl_->leaf_node[leaf]];
  return {impl_->triangle_of_slot.data() + nd.slot_begin, nd.slot_end - nd.slot_begin};
}

}  // namespace hapsim
