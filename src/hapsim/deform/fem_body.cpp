#include "hapsim/deform/fem_body.h"

#include "hapsim/core/error.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <string>
#include <utility>

// The linear systems are solved by a supernodal Cholesky factorisation written here (about 300
// lines) rather than Eigen's SimplicialLDLT: at 20k tetrahedra the simplicial factor is 4.3 M
// scalar entries whose solve streams values and row indices entry by entry (7–8 ms, 1.5 s to
// factor on this machine); the supernodal one stores dense column blocks, solves with dense
// triangular solves and matrix–vector products (2.4 ms, 0.25 s to factor), and in single
// precision (the corotational preconditioner) in 1.4 ms. The ordering is geometric nested
// dissection on the rest node positions (less fill than AMD on tet meshes: 3.5 M against 4.3 M).
// Everything works on 3×3 node blocks: the fixed nodes' rows and columns are simply absent.

namespace hapsim {

namespace {

using FemClock = std::chrono::steady_clock;
using FemVecX = Eigen::VectorXd;

double fem_ms_since(FemClock::time_point t0) {
  return std::chrono::duration<double, std::milli>(FemClock::now() - t0).count();
}

std::size_t fem_sz(std::int32_t i) {
  return static_cast<std::size_t>(i);
}

bool fem_finite(const Vec3& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

std::string fem_number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

// Polar decomposition warm-started from the last rotation, after Müller, Bender, Chentanez and
// Macklin, "A robust method to extract the rotational part of deformations" (MIG 2016): rotate q
// by the angular velocity ω that aligns its axes with A's columns; always a proper rotation, also
// for an inverted A. Their step ω = Σ rᵢ×aᵢ / |Σ rᵢ·aᵢ| converges linearly (by 1/3 a step near
// a small strain: 4 iterations for 1e-2 → 1e-4); near the solution we take the Newton step
// instead, ω = (tr(C)·I − C)⁻¹·Σ rᵢ×aᵢ with C = sym(A·Rᵀ) (from C·exp(−[ω]) symmetric), which
// converges cubically (1e-2 → 3e-7 → 1e-16), and keep theirs where tr(C)·I − C is not safely
// positive definite or the step is large. Returns R = q's matrix.
Mat3 fem_extract_rotation(const Mat3& a, Quat& q, int max_iterations, double tolerance_rad) {
  Mat3 r = q.toRotationMatrix();
  const double tolerance_sq = tolerance_rad * tolerance_rad;
  for (int it = 0; it < max_iterations; ++it) {
    const Mat3 c = a * r.transpose();
    const Vec3 num(c(2, 1) - c(1, 2), c(0, 2) - c(2, 0), c(1, 0) - c(0, 1));  // Σ rᵢ × aᵢ
    const double tr = c.trace();
    // M = tr·I − sym(C); Newton if M is positive definite (leading minors) with a margin.
    const double m00 = tr - c(0, 0);
    const double m11 = tr - c(1, 1);
    const double m22 = tr - c(2, 2);
    const double m01 = -0.5 * (c(0, 1) + c(1, 0));
    const double m02 = -0.5 * (c(0, 2) + c(2, 0));
    const double m12 = -0.5 * (c(1, 2) + c(2, 1));
    const double margin = 1e-3 * std::abs(tr);
    const double minor2 = m00 * m11 - m01 * m01;
    const double cof0 = m11 * m22 - m12 * m12;
    const double cof1 = m02 * m12 - m01 * m22;
    const double cof2 = m01 * m12 - m02 * m11;
    const double det = m00 * cof0 + m01 * cof1 + m02 * cof2;
    Vec3 omega;
    bool newton = false;
    if (m00 > margin && minor2 > margin * m00 && det > margin * minor2) {
      const double cof4 = m00 * m22 - m02 * m02;
      const double cof5 = m02 * m01 - m00 * m12;
      const double cof8 = minor2;
      omega = Vec3(cof0 * num.x() + cof1 * num.y() + cof2 * num.z(),
                   cof1 * num.x() + cof4 * num.y() + cof5 * num.z(),
                   cof2 * num.x() + cof5 * num.y() + cof8 * num.z()) /
              det;
      newton = omega.squaredNorm() < 0.25;
    }
    if (!newton) {
      omega = num / (std::abs(tr) + 1e-9);
    }
    const double w2 = omega.squaredNorm();
    if (!(w2 >= tolerance_sq)) {  // converged (or NaN: keep the last rotation)
      break;
    }
    double cw = 0.0;
    double s_over_w = 0.0;
    if (w2 < 1e-2) {  // cos(w/2), sin(w/2)/w to O(w⁶) < 3e-11
      cw = 1.0 - w2 / 8.0 + w2 * w2 / 384.0;
      s_over_w = 0.5 - w2 / 48.0 + w2 * w2 / 3840.0;
    } else {
      const double w = std::sqrt(w2);
      cw = std::cos(0.5 * w);
      s_over_w = std::sin(0.5 * w) / w;
    }
    const Quat dq(cw, s_over_w * omega.x(), s_over_w * omega.y(), s_over_w * omega.z());
    q = dq * q;
    q.normalize();
    r = q.toRotationMatrix();
    // A Newton step of |ω| leaves about |ω|³/3: below 1e-4 that is below the tolerances used.
    if (newton && w2 < 1e-8 && w2 * w2 * w2 < 9.0 * tolerance_sq) {
      break;
    }
  }
  return r;
}

// ---------------------------------------------------------------------------------------------
// Node graph, ordering, symbolic and numeric supernodal Cholesky.

/// A symmetric graph in CSR: each edge listed from both ends, no self loops.
struct FemGraph {
  std::vector<std::int32_t> start{0};
  std::vector<std::int32_t> adj;
  [[nodiscard]] std::int32_t size() const { return static_cast<std::int32_t>(start.size()) - 1; }
};

/// The graph renumbered: new vertex k is old vertex order[k].
FemGraph fem_permute_graph(const FemGraph& g, const std::vector<std::int32_t>& order) {
  std::vector<std::int32_t> new_of(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    new_of[fem_sz(order[k])] = static_cast<std::int32_t>(k);
  }
  FemGraph out;
  out.start.reserve(order.size() + 1);
  out.adj.reserve(g.adj.size());
  for (const std::int32_t old : order) {
    for (std::int32_t p = g.start[fem_sz(old)]; p < g.start[fem_sz(old) + 1]; ++p) {
      out.adj.push_back(new_of[fem_sz(g.adj[fem_sz(p)])]);
    }
    out.start.push_back(static_cast<std::int32_t>(out.adj.size()));
  }
  return out;
}

/// Geometric nested dissection: split the set at the median of its longest axis; the far-side
/// vertices adjacent to the near side are the separator, numbered after both halves.
void fem_dissect(std::vector<std::int32_t> set, const std::vector<Vec3>& pos, const FemGraph& g,
                 std::vector<std::int32_t>& mark, std::int32_t& tag,
                 std::vector<std::int32_t>& out) {
  constexpr std::size_t kLeafVertices = 24;  // 16–64 all within 5 % on a 20k block
  if (set.size() <= kLeafVertices) {
    out.insert(out.end(), set.begin(), set.end());
    return;
  }
  Box3 box;
  for (const std::int32_t v : set) {
    box.extend(pos[fem_sz(v)]);
  }
  Eigen::Index axis = 0;
  box.sizes().maxCoeff(&axis);
  std::vector<std::int32_t> sorted = set;
  const auto mid = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2);
  std::nth_element(sorted.begin(), mid, sorted.end(), [&](std::int32_t a, std::int32_t b) {
    return pos[fem_sz(a)][axis] < pos[fem_sz(b)][axis];
  });
  const double median = pos[fem_sz(*mid)][axis];
  const std::int32_t near_tag = ++tag;
  std::vector<std::int32_t> near;
  std::vector<std::int32_t> far;
  std::vector<std::int32_t> separator;
  for (const std::int32_t v : set) {
    if (pos[fem_sz(v)][axis] < median) {
      near.push_back(v);
      mark[fem_sz(v)] = near_tag;
    }
  }
  if (near.empty()) {  // all on the median plane: nothing to split
    out.insert(out.end(), set.begin(), set.end());
    return;
  }
  for (const std::int32_t v : set) {
    if (pos[fem_sz(v)][axis] < median) {
      continue;
    }
    bool touches = false;
    for (std::int32_t p = g.start[fem_sz(v)]; p < g.start[fem_sz(v) + 1] && !touches; ++p) {
      touches = mark[fem_sz(g.adj[fem_sz(p)])] == near_tag;
    }
    (touches ? separator : far).push_back(v);
  }
  set.clear();
  set.shrink_to_fit();
  sorted.clear();
  sorted.shrink_to_fit();
  fem_dissect(std::move(near), pos, g, mark, tag, out);
  fem_dissect(std::move(far), pos, g, mark, tag, out);
  out.insert(out.end(), separator.begin(), separator.end());
}

/// Elimination tree (Liu's algorithm with path compression); -1 marks a root.
std::vector<std::int32_t> fem_etree(const FemGraph& g) {
  const std::size_t n = fem_sz(g.size());
  std::vector<std::int32_t> parent(n, -1);
  std::vector<std::int32_t> ancestor(n, -1);
  for (std::int32_t k = 0; k < g.size(); ++k) {
    for (std::int32_t p = g.start[fem_sz(k)]; p < g.start[fem_sz(k) + 1]; ++p) {
      std::int32_t i = g.adj[fem_sz(p)];
      while (i != -1 && i < k) {
        const std::int32_t next = ancestor[fem_sz(i)];
        ancestor[fem_sz(i)] = k;
        if (next == -1) {
          parent[fem_sz(i)] = k;
        }
        i = next;
      }
    }
  }
  return parent;
}

/// Postorder of a forest: order[k] is the vertex numbered k (children before parents, each
/// subtree contiguous), which makes supernodes contiguous without changing the fill.
std::vector<std::int32_t> fem_postorder(const std::vector<std::int32_t>& parent) {
  const std::size_t n = parent.size();
  std::vector<std::int32_t> head(n, -1);
  std::vector<std::int32_t> next(n, -1);
  for (std::size_t j = n; j-- > 0;) {
    if (parent[j] != -1) {
      next[j] = head[fem_sz(parent[j])];
      head[fem_sz(parent[j])] = static_cast<std::int32_t>(j);
    }
  }
  std::vector<std::int32_t> order;
  std::vector<std::int32_t> stack;
  order.reserve(n);
  for (std::size_t root = 0; root < n; ++root) {
    if (parent[root] != -1) {
      continue;
    }
    stack.push_back(static_cast<std::int32_t>(root));
    while (!stack.empty()) {
      const std::int32_t j = stack.back();
      if (head[fem_sz(j)] != -1) {
        const std::int32_t c = head[fem_sz(j)];
        head[fem_sz(j)] = next[fem_sz(c)];
        stack.push_back(c);
      } else {
        stack.pop_back();
        order.push_back(j);
      }
    }
  }
  return order;
}

/// Upper block-sparse pattern (3×3 blocks, row i holds columns j ≥ i, its diagonal first).
struct FemBlockPattern {
  std::vector<std::int32_t> start{0};
  std::vector<std::int32_t> col;
  [[nodiscard]] std::size_t blocks() const { return col.size(); }
  [[nodiscard]] std::int32_t rows() const { return static_cast<std::int32_t>(start.size()) - 1; }
};

/// The factor's structure: supernodes (runs of nodes sharing their column structure below the
/// diagonal block), each stored as a dense column-major (w + rows) × w block, w = 3 × nodes.
struct FemSymbolic {
  std::vector<std::int32_t> first{0};     // supernode → first node; supernodes + 1 entries
  std::vector<std::int32_t> of_node;      // node → supernode
  std::vector<std::size_t> row_start{0};  // supernode → its first entry in `rows`
  std::vector<std::int32_t> rows;         // scalar rows below each diagonal block, ascending
  std::vector<std::size_t> value_start{0};
  std::size_t values = 0;
  std::size_t nonzeros = 0;  // lower triangle, explicit zeros of the relaxed supernodes included
  std::size_t max_off_rows = 0;
  [[nodiscard]] std::int32_t supernodes() const {
    return static_cast<std::int32_t>(first.size()) - 1;
  }
  [[nodiscard]] std::size_t index_bytes() const {
    return rows.size() * sizeof(std::int32_t) +
           (first.size() + of_node.size()) * sizeof(std::int32_t) +
           (row_start.size() + value_start.size()) * sizeof(std::size_t);
  }
};

/// Symbolic factorisation of a postordered graph: column structures by merging the children's
/// (struct(j) = adj⁺(j) ∪ ⋃ struct(child) \ {j}), then fundamental supernodes, relaxed so that
/// chains of up to 4 nodes merge (a few explicit zeros for fewer, larger dense blocks).
FemSymbolic fem_symbolic(const FemGraph& g) {
  constexpr std::int32_t kRelaxNodes = 4;
  FemSymbolic s;
  const std::int32_t n = g.size();
  const std::vector<std::int32_t> parent = fem_etree(g);
  std::vector<std::vector<std::int32_t>> children(fem_sz(n));
  for (std::int32_t j = 0; j < n; ++j) {
    if (parent[fem_sz(j)] != -1) {
      children[fem_sz(parent[fem_sz(j)])].push_back(j);
    }
  }
  std::vector<std::vector<std::int32_t>> structure(fem_sz(n));
  std::vector<std::int32_t> mark(fem_sz(n), -1);
  for (std::int32_t j = 0; j < n; ++j) {
    std::vector<std::int32_t>& sj = structure[fem_sz(j)];
    mark[fem_sz(j)] = j;
    const auto add = [&](std::int32_t i) {
      if (i > j && mark[fem_sz(i)] != j) {
        mark[fem_sz(i)] = j;
        sj.push_back(i);
      }
    };
    for (std::int32_t p = g.start[fem_sz(j)]; p < g.start[fem_sz(j) + 1]; ++p) {
      add(g.adj[fem_sz(p)]);
    }
    for (const std::int32_t c : children[fem_sz(j)]) {
      for (const std::int32_t i : structure[fem_sz(c)]) {
        add(i);
      }
    }
    std::sort(sj.begin(), sj.end());
  }
  // Merging j into the supernode of j−1 needs parent(j−1) = j: then struct(j−1) \ {j} ⊆ struct(j),
  // so the supernode's rows below it are struct(last node) and the fill stays inside the pattern.
  for (std::int32_t j = 1; j < n; ++j) {
    const bool chain = parent[fem_sz(j - 1)] == j;
    const bool fundamental = chain && children[fem_sz(j)].size() == 1 &&
                             structure[fem_sz(j - 1)].size() == structure[fem_sz(j)].size() + 1;
    const bool relaxed = chain && j - s.first.back() < kRelaxNodes;
    if (!fundamental && !relaxed) {
      s.first.push_back(j);
    }
  }
  if (n > 0) {
    s.first.push_back(n);
  }
  s.of_node.assign(fem_sz(n), 0);
  for (std::int32_t k = 0; k < s.supernodes(); ++k) {
    const std::int32_t f = s.first[fem_sz(k)];
    const std::int32_t l = s.first[fem_sz(k) + 1] - 1;
    for (std::int32_t j = f; j <= l; ++j) {
      s.of_node[fem_sz(j)] = k;
    }
    for (const std::int32_t i : structure[fem_sz(l)]) {
      for (std::int32_t a = 0; a < 3; ++a) {
        s.rows.push_back(3 * i + a);
      }
    }
    s.row_start.push_back(s.rows.size());
    const std::size_t w = 3 * fem_sz(l - f + 1);
    const std::size_t off = s.row_start[fem_sz(k) + 1] - s.row_start[fem_sz(k)];
    s.max_off_rows = std::max(s.max_off_rows, off);
    s.value_start.push_back(s.value_start.back() + (w + off) * w);
    s.nonzeros += w * (w + 1) / 2 + w * off;
  }
  s.values = s.value_start.back();
  return s;
}

struct FemFactorWork {
  std::vector<std::int32_t> relpos;
  std::vector<std::int32_t> head;
  std::vector<std::int32_t> next;
  std::vector<std::size_t> consumed;
  std::vector<double> update;
  std::vector<double> diagonal;
};

/// Left-looking supernodal Cholesky L·Lᵀ of the matrix with pattern `pat` (upper blocks) and
/// values `a` (9 per block, column-major). Returns -1, or the first node whose pivot failed
/// (not positive, or below 1e-12 of its diagonal: a singular matrix such as a body whose fixed
/// nodes do not hold it).
std::int32_t fem_factorize(const FemSymbolic& sym, const FemBlockPattern& pat,
                           const std::vector<double>& a, std::vector<double>& lv,
                           FemFactorWork& work) {
  using MatX = Eigen::MatrixXd;
  using Stride = Eigen::OuterStride<>;
  const std::int32_t sn = sym.supernodes();
  lv.assign(sym.values, 0.0);
  work.relpos.assign(3 * fem_sz(pat.rows()), -1);
  work.head.assign(fem_sz(sn), -1);
  work.next.assign(fem_sz(sn), -1);
  work.consumed.assign(fem_sz(sn), 0);
  for (std::int32_t s = 0; s < sn; ++s) {
    const std::int32_t f = sym.first[fem_sz(s)];
    const std::int32_t l = sym.first[fem_sz(s) + 1] - 1;
    const Eigen::Index w = Eigen::Index{3} * (l - f + 1);
    const std::size_t r0 = sym.row_start[fem_sz(s)];
    const std::size_t r1 = sym.row_start[fem_sz(s) + 1];
    const Eigen::Index m = w + static_cast<Eigen::Index>(r1 - r0);
    Eigen::Map<MatX> block(lv.data() + sym.value_start[fem_sz(s)], m, w);
    for (Eigen::Index i = 0; i < w; ++i) {
      work.relpos[fem_sz(3 * f) + static_cast<std::size_t>(i)] = static_cast<std::int32_t>(i);
    }
    for (std::size_t k = r0; k < r1; ++k) {
      work.relpos[fem_sz(sym.rows[k])] =
          static_cast<std::int32_t>(w + static_cast<Eigen::Index>(k - r0));
    }
    // Column node j of the lower triangle is row j of the upper pattern, transposed.
    for (std::int32_t j = f; j <= l; ++j) {
      const Eigen::Index c0 = Eigen::Index{3} * (j - f);
      for (std::int32_t p = pat.start[fem_sz(j)]; p < pat.start[fem_sz(j) + 1]; ++p) {
        const std::int32_t k = pat.col[fem_sz(p)];
        const double* b = a.data() + 9 * fem_sz(p);  // A(j, k), column-major
        for (std::int32_t r = 0; r < 3; ++r) {
          const Eigen::Index row = work.relpos[fem_sz(3 * k + r)];
          for (Eigen::Index c = 0; c < 3; ++c) {
            block(row, c0 + c) += b[Eigen::Index{3} * r + c];  // A(k, j)(r, c) = A(j, k)(c, r)
          }
        }
      }
    }
    work.diagonal.resize(static_cast<std::size_t>(w));
    for (Eigen::Index i = 0; i < w; ++i) {
      work.diagonal[static_cast<std::size_t>(i)] = block(i, i);
    }
    // Updates from every earlier supernode d with rows in this one's columns (linked lists as in
    // CHOLMOD: d waits in the list of the supernode owning its next unconsumed row).
    for (std::int32_t d = work.head[fem_sz(s)]; d != -1;) {
      const std::int32_t d_next = work.next[fem_sz(d)];
      const Eigen::Index wd = Eigen::Index{3} * (sym.first[fem_sz(d) + 1] - sym.first[fem_sz(d)]);
      const std::size_t dr0 = sym.row_start[fem_sz(d)];
      const std::size_t dr1 = sym.row_start[fem_sz(d) + 1];
      const Eigen::Index md = wd + static_cast<Eigen::Index>(dr1 - dr0);
      const std::size_t p0 = dr0 + work.consumed[fem_sz(d)];
      std::size_t p1 = p0;
      while (p1 < dr1 && sym.rows[p1] < 3 * (l + 1)) {
        ++p1;
      }
      const Eigen::Index all = static_cast<Eigen::Index>(dr1 - p0);
      const Eigen::Index top = static_cast<Eigen::Index>(p1 - p0);
      const Eigen::Map<const MatX, 0, Stride> ld(lv.data() + sym.value_start[fem_sz(d)] +
                                                     static_cast<std::size_t>(wd) +
                                                     work.consumed[fem_sz(d)],
                                                 all, wd, Stride(md));
      const std::size_t need = static_cast<std::size_t>(all * top);
      if (work.update.size() < need) {
        work.update.resize(need);
      }
      Eigen::Map<MatX> upd(work.update.data(), all, top);
      upd.noalias() = ld * ld.topRows(top).transpose();
      for (Eigen::Index jc = 0; jc < top; ++jc) {
        const Eigen::Index col = work.relpos[fem_sz(sym.rows[p0 + static_cast<std::size_t>(jc)])];
        for (Eigen::Index ir = jc; ir < all; ++ir) {
          block(work.relpos[fem_sz(sym.rows[p0 + static_cast<std::size_t>(ir)])], col) -=
              upd(ir, jc);
        }
      }
      work.consumed[fem_sz(d)] += static_cast<std::size_t>(top);
      if (p1 < dr1) {
        const std::int32_t target = sym.of_node[fem_sz(sym.rows[p1] / 3)];
        work.next[fem_sz(d)] = work.head[fem_sz(target)];
        work.head[fem_sz(target)] = d;
      }
      d = d_next;
    }
    auto diag = block.topLeftCorner(w, w);
    Eigen::Ref<MatX> diag_ref(diag);
    const Eigen::LLT<Eigen::Ref<MatX>> llt(diag_ref);  // in place (Eigen's blocked LLᵀ)
    for (Eigen::Index i = 0; i < w; ++i) {
      const double pivot = diag(i, i) * diag(i, i);
      if (!(pivot > 1e-12 * work.diagonal[static_cast<std::size_t>(i)])) {
        return f + static_cast<std::int32_t>(i / 3);
      }
    }
    if (llt.info() != Eigen::Success) {
      return f;
    }
    if (m > w) {
      auto below = block.bottomRows(m - w);
      diag.transpose().triangularView<Eigen::Upper>().solveInPlace<Eigen::OnTheRight>(below);
      const std::int32_t target = sym.of_node[fem_sz(sym.rows[r0] / 3)];
      work.next[fem_sz(s)] = work.head[fem_sz(target)];
      work.head[fem_sz(target)] = s;
    }
  }
  return -1;
}

/// y ← (L·Lᵀ)⁻¹·y with the supernodal factor `lv` (double, or its float copy); `t` holds at
/// least max_off_rows scalars. Dense triangular solves and matrix–vector products per
/// supernode; allocates nothing.
template <typename Scalar>
void fem_solve_in_place(const FemSymbolic& sym, const Scalar* lv, Scalar* y, Scalar* t) {
  using Mat = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  using Vec = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
  const std::int32_t sn = sym.supernodes();
  for (std::int32_t s = 0; s < sn; ++s) {
    const std::int32_t f = sym.first[fem_sz(s)];
    const Eigen::Index w = Eigen::Index{3} * (sym.first[fem_sz(s) + 1] - f);
    const std::size_t r0 = sym.row_start[fem_sz(s)];
    const Eigen::Index nr = static_cast<Eigen::Index>(sym.row_start[fem_sz(s) + 1] - r0);
    const Eigen::Map<const Mat> block(lv + sym.value_start[fem_sz(s)], w + nr, w);
    Eigen::Map<Vec> ys(y + 3 * f, w);
    block.topRows(w).template triangularView<Eigen::Lower>().solveInPlace(ys);
    if (nr > 0) {
      Eigen::Map<Vec> tv(t, nr);
      tv.noalias() = block.bottomRows(nr) * ys;
      const std::int32_t* rows = sym.rows.data() + r0;
      for (Eigen::Index k = 0; k < nr; ++k) {
        y[rows[k]] -= t[k];
      }
    }
  }
  for (std::int32_t s = sn; s-- > 0;) {
    const std::int32_t f = sym.first[fem_sz(s)];
    const Eigen::Index w = Eigen::Index{3} * (sym.first[fem_sz(s) + 1] - f);
    const std::size_t r0 = sym.row_start[fem_sz(s)];
    const Eigen::Index nr = static_cast<Eigen::Index>(sym.row_start[fem_sz(s) + 1] - r0);
    const Eigen::Map<const Mat> block(lv + sym.value_start[fem_sz(s)], w + nr, w);
    Eigen::Map<Vec> ys(y + 3 * f, w);
    if (nr > 0) {
      const std::int32_t* rows = sym.rows.data() + r0;
      for (Eigen::Index k = 0; k < nr; ++k) {
        t[k] = y[rows[k]];
      }
      const Eigen::Map<const Vec> tv(t, nr);
      ys.noalias() -= block.bottomRows(nr).transpose() * tv;
    }
    block.topRows(w).transpose().template triangularView<Eigen::Upper>().solveInPlace(ys);
  }
}

/// y = A·x for a symmetric matrix stored as upper 3×3 blocks.
void fem_spmv(const FemBlockPattern& pat, const std::vector<double>& values, const FemVecX& x,
              FemVecX& y) {
  y.setZero();
  const std::int32_t n = pat.rows();
  for (std::int32_t i = 0; i < n; ++i) {
    const Vec3 xi = x.segment<3>(Eigen::Index{3} * i);
    std::int32_t p = pat.start[fem_sz(i)];
    Vec3 yi = Eigen::Map<const Mat3>(values.data() + 9 * fem_sz(p)) * xi;  // diagonal block
    for (++p; p < pat.start[fem_sz(i) + 1]; ++p) {
      const std::int32_t j = pat.col[fem_sz(p)];
      const Eigen::Map<const Mat3> b(values.data() + 9 * fem_sz(p));
      yi.noalias() += b * x.segment<3>(Eigen::Index{3} * j);
      y.segment<3>(Eigen::Index{3} * j).noalias() += b.transpose() * xi;
    }
    y.segment<3>(Eigen::Index{3} * i) += yi;
  }
}

// Node pairs of a tet whose 3×3 stiffness blocks are stored (the diagonal ones, then i < j).
constexpr std::array<std::array<int, 2>, 10> kFemPairs{
    {{0, 0}, {1, 1}, {2, 2}, {3, 3}, {0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};

struct FemElement {
  TetIndices node{};
  std::uint32_t tet = 0;  // index in the mesh (elements are stored in solver order)
  /// Dm⁻¹ of the rest shape (Dm = [X1−X0, X2−X0, X3−X0]): its rows are the gradients of shape
  /// functions 1..3, so F = Ds·Dm⁻¹ = Σ xᵢ·gᵢᵀ.
  Mat3 dm_inv = Mat3::Identity();
  double volume_m3 = 0.0;
  double lambda_v = 0.0;       // Lamé λ·V, N·m
  double mu_v = 0.0;           // μ·V
  double dynamic_scale = 0.0;  // weight of Kₑ in A = M + dt·C + dt²·K: dt·β + dt²
  std::int32_t material = 0;
  /// Block of each kFemPairs pair in the block pattern (-1: a fixed node), and which are stored
  /// transposed (the pair's first node has the larger free index).
  std::array<std::int32_t, 10> slot{};
  std::uint16_t transposed = 0;
};

struct FemFactor {
  std::vector<double> values;   // double factor (empty when only the float copy is kept)
  std::vector<float> values_f;  // float copy: the corotational preconditioner
  [[nodiscard]] bool empty() const { return values.empty() && values_f.empty(); }
  [[nodiscard]] std::size_t bytes() const {
    return values.size() * sizeof(double) + values_f.size() * sizeof(float);
  }
};

struct FemPcgResult {
  int iterations = 0;
  double residual_relative = 0.0;
  bool converged = true;
};

enum class FemPass : std::uint8_t { kForces, kStiffness, kDynamic };

// Rotations in a step: warm-started, one Newton iteration when they turned by less than 1.4e-3
// rad since the last step (its error ~|ω|³/3 is then below 1e-9 rad: a relative force error of
// 1e-9 over the strain, nothing at all for a step). Queries and new states converge further.
constexpr int kFemStepPolarIterations = 4;
constexpr double kFemStepPolarTolerance = 1e-9;  // rad
constexpr int kFemQueryPolarIterations = 60;     // from far away (a jump, a set state)
constexpr double kFemPolarTolerance = 1e-11;     // rad
constexpr int kFemMaxStaticIterations = 100;
constexpr int kFemMaxContactRounds = 30;

}  // namespace

std::string_view to_string(FemElasticity elasticity) {
  switch (elasticity) {
    case FemElasticity::kLinear:
      return "linear";
    case FemElasticity::kCorotational:
      return "corotational";
  }
  return "unknown";
}

std::string_view to_string(FemIntegration integration) {
  switch (integration) {
    case FemIntegration::kBackwardEuler:
      return "backward_euler";
    case FemIntegration::kQuasiStatic:
      return "quasi_static";
  }
  return "unknown";
}

struct FemBody::Impl {
  TetMesh mesh;
  FemOptions options;
  std::string source;
  bool corotational = true;
  bool dynamic = true;

  std::vector<FemElement> elements;
  std::vector<FemMaterial> materials;
  std::vector<double> node_mass_kg;  // every node
  double total_mass_kg = 0.0;

  std::vector<std::uint32_t> fixed;          // sorted, unique
  std::vector<std::int32_t> free_index;      // node → free index, -1 for fixed (and unused) nodes
  std::vector<std::uint32_t> free_node;      // free index → node
  std::vector<std::uint32_t> boundary_free;  // free nodes on the boundary (contact candidates)
  std::vector<std::uint32_t> node_tet_start;  // node → its elements (CSR, element positions)
  std::vector<std::uint32_t> node_tets;
  std::vector<std::uint32_t> fixed_tets;  // elements with a fixed node (linear: fixed coupling)

  // State, every node.
  std::vector<Vec3> x;
  std::vector<Vec3> vel;
  std::vector<Vec3> f_ext;
  std::vector<Vec3> f_el;
  std::vector<Quat> element_q;
  std::size_t rejected = 0;

  // Per free node.
  std::vector<double> mass_free;     // m
  std::vector<double> mass_dynamic;  // (1 + dt·α)·m summed over elements
  /// Node frames for the preconditioner: the rotation of the node's first tet (as good as the
  /// average of its tets' for preconditioning, and free: no accumulation, no polar).
  std::vector<Mat3> node_r;

  // Matrices (3×3 blocks over free nodes) and factors.
  FemBlockPattern pattern;
  std::vector<double> k_values;     // rest K
  std::vector<double> work_values;  // K_R, A_R, or K + contact penalties
  FemSymbolic symbolic;
  FemFactor factor_a;  // M + dt·C + dt²·K (backward Euler)
  FemFactor factor_k;  // K (quasi-static, statics, compliance)
  FemFactor factor_contact;
  FemFactorWork factor_work;
  double factor_ms = 0.0;

  // Solver buffers (3 per free node).
  FemVecX rhs, sol, res, pre, dir, prod, coupling, u;
  FemVecX vel_previous;  // the free nodes' velocities a step ago (the CG warm start)
  Eigen::VectorXf pre_f;
  std::vector<double> solve_tmp;
  std::vector<float> solve_tmp_f;
  std::vector<Vec3> scratch_x;

  // --- construction -------------------------------------------------------------------------
  Impl(TetMesh mesh_in, const std::vector<FemRegionMaterial>& region_materials,
       std::vector<std::uint32_t> fixed_nodes, const FemOptions& opts, std::string_view src)
      : mesh(std::move(mesh_in)), options(opts), source(src) {
    corotational = options.elasticity == FemElasticity::kCorotational;
    dynamic = options.integration == FemIntegration::kBackwardEuler;
    check_options();
    validate_tet_mesh(mesh, source);
    setup_materials(region_materials);
    setup_fixed(std::move(fixed_nodes));
    setup_elements();
    setup_ordering_and_pattern();
    assemble_rest_and_factor();
    allocate_state();
  }

  [[noreturn]] void fail(const std::string& what) const { throw Error(source, what); }

  void check_options() const {
    if (!std::isfinite(options.dt_s) || options.dt_s <= 0.0) {
      fail("dt_s must be a finite time > 0 s, got " + fem_number(options.dt_s));
    }
    if (!fem_finite(options.gravity_m_per_s2)) {
      fail("gravity_m_per_s2 must be finite");
    }
    if (options.max_cg_iterations < 1) {
      fail("max_cg_iterations must be >= 1, got " + std::to_string(options.max_cg_iterations));
    }
    if (!std::isfinite(options.cg_relative_tolerance) || options.cg_relative_tolerance <= 0.0 ||
        options.cg_relative_tolerance >= 1.0) {
      fail("cg_relative_tolerance must be in (0, 1), got " +
           fem_number(options.cg_relative_tolerance));
    }
    if (options.quasi_static_iterations < 1) {
      fail("quasi_static_iterations must be >= 1, got " +
           std::to_string(options.quasi_static_iterations));
    }
  }

  void setup_materials(const std::vector<FemRegionMaterial>& region_materials) {
    for (std::size_t i = 0; i < region_materials.size(); ++i) {
      const FemRegionMaterial& rm = region_materials[i];
      const FemMaterial& m = rm.material;
      const std::string where =
          "materials[" + std::to_string(i) + "] (region " + std::to_string(rm.region) + "): ";
      if (!std::isfinite(m.youngs_modulus_pa) || m.youngs_modulus_pa <= 0.0) {
        fail(where + "Young's modulus must be finite and > 0 Pa, got " +
             fem_number(m.youngs_modulus_pa));
      }
      if (!std::isfinite(m.poisson_ratio) || m.poisson_ratio < 0.0 || m.poisson_ratio >= 0.5) {
        fail(where + "Poisson ratio must be in [0, 0.5), got " + fem_number(m.poisson_ratio));
      }
      if (!std::isfinite(m.density_kg_per_m3) || m.density_kg_per_m3 <= 0.0) {
        fail(where + "density must be finite and > 0 kg/m^3, got " +
             fem_number(m.density_kg_per_m3));
      }
      if (!std::isfinite(m.rayleigh_mass_per_s) || m.rayleigh_mass_per_s < 0.0 ||
          !std::isfinite(m.rayleigh_stiffness_s) || m.rayleigh_stiffness_s < 0.0) {
        fail(where + "Rayleigh damping must be finite and >= 0, got alpha " +
             fem_number(m.rayleigh_mass_per_s) + " 1/s, beta " +
             fem_number(m.rayleigh_stiffness_s) + " s");
      }
      for (std::size_t k = 0; k < i; ++k) {
        if (region_materials[k].region == rm.region) {
          fail(where + "region " + std::to_string(rm.region) + " already has materials[" +
               std::to_string(k) + "]");
        }
      }
      materials.push_back(m);
    }
    elements.resize(mesh.tet_count());
    for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
      const std::int32_t region = mesh.region(t);
      std::int32_t found = -1;
      for (std::size_t i = 0; i < region_materials.size() && found < 0; ++i) {
        if (region_materials[i].region == region) {
          found = static_cast<std::int32_t>(i);
        }
      }
      if (found < 0) {
        fail("region " + std::to_string(region) + " (element " + std::to_string(t) +
             " is the first in it) has no material");
      }
      elements[t].material = found;
    }
  }

  void setup_fixed(std::vector<std::uint32_t> fixed_nodes) {
    for (const std::uint32_t n : fixed_nodes) {
      if (n >= mesh.node_count()) {
        fail("fixed node " + std::to_string(n) + " is out of range (the mesh has " +
             std::to_string(mesh.node_count()) + " nodes)");
      }
    }
    std::sort(fixed_nodes.begin(), fixed_nodes.end());
    fixed_nodes.erase(std::unique(fixed_nodes.begin(), fixed_nodes.end()), fixed_nodes.end());
    if (fixed_nodes.empty()) {
      fail(
          "no fixed node: a free body is singular under quasi-static loads (fix at least three "
          "non-collinear nodes, e.g. the ones attached to a bone)");
    }
    fixed = std::move(fixed_nodes);
  }

  void setup_elements() {
    const std::size_t n = mesh.node_count();
    node_mass_kg.assign(n, 0.0);
    std::vector<double> mass_dyn(n, 0.0);
    std::vector<char> used(n, 0);
    for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
      FemElement& el = elements[t];
      el.node = mesh.tets[t];
      el.tet = static_cast<std::uint32_t>(t);
      const FemMaterial& m = materials[fem_sz(el.material)];
      Mat3 dm;
      for (int c = 0; c < 3; ++c) {
        dm.col(c) = mesh.nodes[el.node[fem_sz(c + 1)]] - mesh.nodes[el.node[0]];
      }
      el.volume_m3 = dm.determinant() / 6.0;
      el.dm_inv = dm.inverse();
      const double e = m.youngs_modulus_pa;
      const double nu = m.poisson_ratio;
      el.lambda_v = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)) * el.volume_m3;
      el.mu_v = e / (2.0 * (1.0 + nu)) * el.volume_m3;
      const double dt = options.dt_s;
      el.dynamic_scale = dt * m.rayleigh_stiffness_s + dt * dt;
      const double quarter = m.density_kg_per_m3 * el.volume_m3 / 4.0;
      total_mass_kg += 4.0 * quarter;
      for (const std::uint32_t v : el.node) {
        node_mass_kg[v] += quarter;
        mass_dyn[v] += (1.0 + dt * m.rayleigh_mass_per_s) * quarter;
        used[v] = 1;
      }
    }
    // Free nodes: used by a tet and not fixed (an unused node has no stiffness: it stays put).
    std::vector<char> is_fixed(n, 0);
    for (const std::uint32_t f : fixed) {
      is_fixed[f] = 1;
    }
    free_index.assign(n, -1);
    for (std::size_t i = 0; i < n; ++i) {
      if (used[i] && !is_fixed[i]) {
        free_index[i] = static_cast<std::int32_t>(free_node.size());
        free_node.push_back(static_cast<std::uint32_t>(i));
      }
    }
    // The mass per free node is gathered after the final numbering (setup_ordering_and_pattern).
    mass_free.assign(free_node.size(), 0.0);
    mass_dynamic.assign(free_node.size(), 0.0);
    for (std::size_t k = 0; k < free_node.size(); ++k) {
      mass_free[k] = node_mass_kg[free_node[k]];
      mass_dynamic[k] = mass_dyn[free_node[k]];
    }
    // Boundary nodes: on a face that belongs to one tet only.
    std::vector<std::array<std::uint32_t, 3>> faces;
    faces.reserve(4 * mesh.tet_count());
    for (const TetIndices& t : mesh.tets) {
      for (int skip = 0; skip < 4; ++skip) {
        std::array<std::uint32_t, 3> f{};
        int k = 0;
        for (int i = 0; i < 4; ++i) {
          if (i != skip) {
            f[fem_sz(k++)] = t[fem_sz(i)];
          }
        }
        std::sort(f.begin(), f.end());
        faces.push_back(f);
      }
    }
    std::sort(faces.begin(), faces.end());
    std::vector<char> on_boundary(n, 0);
    for (std::size_t i = 0; i < faces.size();) {
      std::size_t j = i + 1;
      while (j < faces.size() && faces[j] == faces[i]) {
        ++j;
      }
      if (j - i == 1) {
        for (const std::uint32_t v : faces[i]) {
          on_boundary[v] = 1;
        }
      }
      i = j;
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (on_boundary[i] && free_index[i] >= 0) {
        boundary_free.push_back(static_cast<std::uint32_t>(i));
      }
    }
  }

  void setup_ordering_and_pattern() {
    const std::size_t nf = free_node.size();
    // Node graph over free nodes (mesh order).
    std::vector<std::vector<std::int32_t>> neighbours(nf);
    for (const TetIndices& t : mesh.tets) {
      for (int a = 0; a < 4; ++a) {
        const std::int32_t fa = free_index[t[fem_sz(a)]];
        if (fa < 0) {
          continue;
        }
        for (int b = 0; b < 4; ++b) {
          const std::int32_t fb = free_index[t[fem_sz(b)]];
          if (b != a && fb >= 0) {
            neighbours[fem_sz(fa)].push_back(fb);
          }
        }
      }
    }
    FemGraph g0;
    for (auto& list : neighbours) {
      std::sort(list.begin(), list.end());
      list.erase(std::unique(list.begin(), list.end()), list.end());
      g0.adj.insert(g0.adj.end(), list.begin(), list.end());
      g0.start.push_back(static_cast<std::int32_t>(g0.adj.size()));
      list.clear();
      list.shrink_to_fit();
    }
    // Nested dissection, then the elimination tree's postorder.
    std::vector<Vec3> pos(nf);
    for (std::size_t k = 0; k < nf; ++k) {
      pos[k] = mesh.nodes[free_node[k]];
    }
    std::vector<std::int32_t> order;
    order.reserve(nf);
    {
      std::vector<std::int32_t> all(nf);
      std::iota(all.begin(), all.end(), 0);
      std::vector<std::int32_t> mark(nf, 0);
      std::int32_t tag = 0;
      fem_dissect(std::move(all), pos, g0, mark, tag, order);
    }
    const FemGraph g1 = fem_permute_graph(g0, order);
    const std::vector<std::int32_t> post = fem_postorder(fem_etree(g1));
    std::vector<std::int32_t> final_order(nf);
    for (std::size_t k = 0; k < nf; ++k) {
      final_order[k] = order[fem_sz(post[k])];
    }
    const FemGraph g = fem_permute_graph(g0, final_order);
    // Renumber the free nodes.
    std::vector<std::uint32_t> new_free_node(nf);
    std::vector<double> new_mass(nf);
    std::vector<double> new_mass_dyn(nf);
    for (std::size_t k = 0; k < nf; ++k) {
      const std::size_t old = fem_sz(final_order[k]);
      new_free_node[k] = free_node[old];
      new_mass[k] = mass_free[old];
      new_mass_dyn[k] = mass_dynamic[old];
    }
    free_node = std::move(new_free_node);
    mass_free = std::move(new_mass);
    mass_dynamic = std::move(new_mass_dyn);
    for (std::size_t k = 0; k < nf; ++k) {
      free_index[free_node[k]] = static_cast<std::int32_t>(k);
    }
    symbolic = fem_symbolic(g);
    // Upper block pattern.
    for (std::int32_t i = 0; i < g.size(); ++i) {
      pattern.col.push_back(i);
      for (std::int32_t p = g.start[fem_sz(i)]; p < g.start[fem_sz(i) + 1]; ++p) {
        if (g.adj[fem_sz(p)] > i) {
          pattern.col.push_back(g.adj[fem_sz(p)]);
        }
      }
      std::sort(pattern.col.begin() + pattern.start.back() + 1, pattern.col.end());
      pattern.start.push_back(static_cast<std::int32_t>(pattern.col.size()));
    }
    // Elements in the order of their first free node, so that assembly writes the blocks
    // roughly in order (30 % faster than mesh order on a 20k block).
    const auto first_free = [&](const FemElement& el) {
      std::int32_t k = std::numeric_limits<std::int32_t>::max();
      for (const std::uint32_t node : el.node) {
        if (free_index[node] >= 0) {
          k = std::min(k, free_index[node]);
        }
      }
      return k;
    };
    std::stable_sort(
        elements.begin(), elements.end(),
        [&](const FemElement& a, const FemElement& b) { return first_free(a) < first_free(b); });
    // Node → elements (positions in `elements`), and the elements touching a fixed node.
    const std::size_t n = mesh.node_count();
    node_tet_start.assign(n + 1, 0);
    for (const FemElement& el : elements) {
      for (const std::uint32_t v : el.node) {
        ++node_tet_start[v + 1];
      }
    }
    std::partial_sum(node_tet_start.begin(), node_tet_start.end(), node_tet_start.begin());
    node_tets.resize(node_tet_start.back());
    std::vector<std::uint32_t> fill(node_tet_start.begin(), node_tet_start.end() - 1);
    for (std::size_t e = 0; e < elements.size(); ++e) {
      bool touches_fixed = false;
      for (const std::uint32_t v : elements[e].node) {
        node_tets[fill[v]++] = static_cast<std::uint32_t>(e);
        touches_fixed = touches_fixed || free_index[v] < 0;
      }
      if (touches_fixed) {
        fixed_tets.push_back(static_cast<std::uint32_t>(e));
      }
    }
    // Each element block's place in the pattern: assembly is then a scatter.
    for (FemElement& el : elements) {
      el.transposed = 0;
      for (std::size_t p = 0; p < kFemPairs.size(); ++p) {
        const std::int32_t fa = free_index[el.node[fem_sz(kFemPairs[p][0])]];
        const std::int32_t fb = free_index[el.node[fem_sz(kFemPairs[p][1])]];
        if (fa < 0 || fb < 0) {
          el.slot[p] = -1;
          continue;
        }
        const std::int32_t row = std::min(fa, fb);
        const std::int32_t col = std::max(fa, fb);
        const auto begin = pattern.col.begin() + pattern.start[fem_sz(row)];
        const auto end = pattern.col.begin() + pattern.start[fem_sz(row) + 1];
        el.slot[p] =
            static_cast<std::int32_t>(std::lower_bound(begin, end, col) - pattern.col.begin());
        if (fa > fb) {
          el.transposed = static_cast<std::uint16_t>(el.transposed | (1U << p));
        }
      }
    }
  }

  /// Adds c·R·Kₑ·Rᵀ of every element into `values` (h = R·gradients): block (a, b) is
  /// V·(λ·hₐ·h_bᵀ + μ·h_b·hₐᵀ + μ·(hₐ·h_b)·I).
  static void add_element_blocks(const FemElement& el, const Mat3& h3, double scale,
                                 std::vector<double>& values) {
    const std::array<Vec3, 4> h{-(h3.col(0) + h3.col(1) + h3.col(2)), h3.col(0), h3.col(1),
                                h3.col(2)};
    const double lv = scale * el.lambda_v;
    const double mv = scale * el.mu_v;
    std::array<Vec3, 4> lh;
    std::array<Vec3, 4> mh;
    for (std::size_t i = 0; i < 4; ++i) {
      lh[i] = lv * h[i];
      mh[i] = mv * h[i];
    }
    for (std::size_t p = 0; p < kFemPairs.size(); ++p) {
      const std::int32_t slot = el.slot[p];
      if (slot < 0) {
        continue;
      }
      std::size_t a = fem_sz(kFemPairs[p][0]);
      std::size_t b = fem_sz(kFemPairs[p][1]);
      if ((el.transposed >> p) & 1U) {
        std::swap(a, b);
      }
      double* blk = values.data() + 9 * fem_sz(slot);  // column-major
      const double diag = mh[a].dot(h[b]);
      for (Eigen::Index c = 0; c < 3; ++c) {
        for (Eigen::Index r = 0; r < 3; ++r) {
          blk[3 * c + r] += lh[a][r] * h[b][c] + mh[b][r] * h[a][c];
        }
        blk[4 * c] += diag;
      }
    }
  }

  void add_mass_diagonal(const std::vector<double>& mass, std::vector<double>& values) const {
    for (std::int32_t i = 0; i < pattern.rows(); ++i) {
      Eigen::Map<Mat3> blk(values.data() + 9 * fem_sz(pattern.start[fem_sz(i)]));
      blk.diagonal().array() += mass[fem_sz(i)];
    }
  }

  void factorize_into(const std::vector<double>& values, FemFactor& factor, bool keep_double,
                      bool keep_float, const char* what) {
    const std::int32_t bad = fem_factorize(symbolic, pattern, values, factor.values, factor_work);
    if (bad >= 0) {
      const std::uint32_t node = free_node[fem_sz(bad)];
      fail(std::string("factorising ") + what + " failed at node " + std::to_string(node) +
           " (not positive definite: do the fixed nodes hold every part of the body? a "
           "single fixed node leaves it free to rotate)");
    }
    if (keep_float) {
      factor.values_f.assign(factor.values.begin(), factor.values.end());
    }
    if (!keep_double) {
      factor.values.clear();
      factor.values.shrink_to_fit();
    }
  }

  void assemble_rest_and_factor() {
    const auto t0 = FemClock::now();
    k_values.assign(9 * pattern.blocks(), 0.0);
    for (const FemElement& el : elements) {
      add_element_blocks(el, el.dm_inv.transpose(), 1.0, k_values);
    }
    // K: exact solves (linear statics, compliance) in double; the corotational quasi-static
    // preconditioner in float.
    factorize_into(k_values, factor_k, true, corotational && !dynamic, "the stiffness K");
    if (dynamic) {
      work_values.assign(k_values.size(), 0.0);
      for (const FemElement& el : elements) {
        add_element_blocks(el, el.dm_inv.transpose(), el.dynamic_scale, work_values);
      }
      add_mass_diagonal(mass_dynamic, work_values);
      factorize_into(work_values, factor_a, !corotational, corotational,
                     "the backward Euler matrix M + dt*C + dt^2*K");
    }
    factor_ms = fem_ms_since(t0);
    factor_work.update.clear();
    factor_work.update.shrink_to_fit();
  }

  void allocate_state() {
    const std::size_t n = mesh.node_count();
    const std::size_t nf = free_node.size();
    const auto dofs = static_cast<Eigen::Index>(3 * nf);
    x = mesh.nodes;
    vel.assign(n, Vec3::Zero());
    f_ext.assign(n, Vec3::Zero());
    f_el.assign(n, Vec3::Zero());
    scratch_x.assign(n, Vec3::Zero());
    element_q.assign(elements.size(), Quat::Identity());
    node_r.assign(nf, Mat3::Identity());
    work_values.assign(k_values.size(), 0.0);
    for (FemVecX* vec : {&rhs, &sol, &res, &pre, &dir, &prod, &coupling, &u, &vel_previous}) {
      vec->setZero(dofs);
    }
    pre_f.setZero(dofs);
    solve_tmp.assign(symbolic.max_off_rows + 1, 0.0);
    solve_tmp_f.assign(symbolic.max_off_rows + 1, 0.0F);
  }

  // --- element kinematics ---------------------------------------------------------------------

  [[nodiscard]] Mat3 deformation_gradient(const FemElement& el,
                                          const std::vector<Vec3>& pos) const {
    Mat3 ds;
    const Vec3& p0 = pos[el.node[0]];
    ds.col(0) = pos[el.node[1]] - p0;
    ds.col(1) = pos[el.node[2]] - p0;
    ds.col(2) = pos[el.node[3]] - p0;
    return ds * el.dm_inv;
  }

  /// Small strain of S (= Rᵀ·F, or F for the linear model) and V·σ.
  static Mat3 strain_of(const Mat3& s) {
    Mat3 eps = 0.5 * (s + s.transpose());
    eps.diagonal().array() -= 1.0;
    return eps;
  }
  static Mat3 stress_times_volume(const FemElement& el, const Mat3& eps) {
    Mat3 sigma_v = (2.0 * el.mu_v) * eps;
    sigma_v.diagonal().array() += el.lambda_v * eps.trace();
    return sigma_v;
  }

  /// Element e's rotation at positions `pos` for a query (the linear model: I).
  [[nodiscard]] Mat3 query_rotation(std::size_t e, const Mat3& f) const {
    if (!corotational) {
      return Mat3::Identity();
    }
    Quat q = element_q[e];
    return fem_extract_rotation(f, q, kFemQueryPolarIterations, kFemPolarTolerance);
  }

  /// The hot loop: for every element at the current positions its rotation (warm-started), its
  /// elastic force into f_el, and (kStiffness, kDynamic) its rotated stiffness scattered into
  /// work_values; then the node frames. One pass over the elements.
  void element_pass(FemPass pass, int polar_iterations,
                    double polar_tolerance = kFemStepPolarTolerance) {
    std::fill(f_el.begin(), f_el.end(), Vec3::Zero());
    const bool assemble = pass != FemPass::kForces;
    if (assemble) {
      std::fill(work_values.begin(), work_values.end(), 0.0);
    }
    for (std::size_t e = 0; e < elements.size(); ++e) {
      const FemElement& el = elements[e];
      const Mat3 f = deformation_gradient(el, x);
      const Mat3 r = corotational
                         ? fem_extract_rotation(f, element_q[e], polar_iterations, polar_tolerance)
                         : Mat3::Identity();
      const Mat3 eps = strain_of(r.transpose() * f);
      const Mat3 gt = el.dm_inv.transpose();  // columns g1..g3
      const Mat3 h = r * gt;                  // rotated gradients
      // fᵢ = −V·R·σ·gᵢ = −(R·σV)·gᵢ: −∂(energy)/∂xᵢ with R held.
      const Mat3 forces = -(r * stress_times_volume(el, eps)) * gt;
      f_el[el.node[1]] += forces.col(0);
      f_el[el.node[2]] += forces.col(1);
      f_el[el.node[3]] += forces.col(2);
      f_el[el.node[0]] -= forces.col(0) + forces.col(1) + forces.col(2);
      if (assemble) {
        add_element_blocks(el, h, pass == FemPass::kDynamic ? el.dynamic_scale : 1.0, work_values);
      }
    }
    if (pass == FemPass::kDynamic) {
      add_mass_diagonal(mass_dynamic, work_values);
    }
    if (corotational) {
      for (std::size_t k = 0; k < free_node.size(); ++k) {
        node_r[k] = element_q[node_tets[node_tet_start[free_node[k]]]].toRotationMatrix();
      }
    }
  }

  /// Linear model: −K·u on the free nodes' rows, fixed nodes' displacements included.
  void linear_elastic_force(FemVecX& out) {
    for (std::size_t k = 0; k < free_node.size(); ++k) {
      u.segment<3>(static_cast<Eigen::Index>(3 * k)) = x[free_node[k]] - mesh.nodes[free_node[k]];
    }
    fem_spmv(pattern, k_values, u, out);
    out = coupling - out;
  }

  /// Linear model: −K_fc·u_c, the free rows' force from the fixed nodes' displacements (they
  /// move with set_fixed_positions), element by element over the tets that touch a fixed node.
  void update_fixed_coupling() {
    coupling.setZero();
    if (corotational) {
      return;
    }
    for (const std::uint32_t t : fixed_tets) {
      const FemElement& el = elements[t];
      for (const std::uint32_t node : el.node) {
        scratch_x[node] = free_index[node] >= 0 ? mesh.nodes[node] : x[node];
      }
      const Mat3 f = deformation_gradient(el, scratch_x);
      const Mat3 gt = el.dm_inv.transpose();
      const Mat3 forces = -stress_times_volume(el, strain_of(f)) * gt;
      const std::array<Vec3, 4> fn{-(forces.col(0) + forces.col(1) + forces.col(2)), forces.col(0),
                                   forces.col(1), forces.col(2)};
      for (std::size_t a = 0; a < 4; ++a) {
        const std::int32_t fi = free_index[el.node[a]];
        if (fi >= 0) {
          coupling.segment<3>(Eigen::Index{3} * fi) += fn[a];
        }
      }
    }
  }

  /// External + gravity (+ elastic f_el from element_pass, when `with_f_el`) on the free rows.
  /// Returns the size of the forces summed, ‖f_ext + f_g‖ + ‖f_el‖: the scale of CG's residual
  /// (the sum itself vanishes at equilibrium, where a fraction of it would ask ever more).
  double gather_forces(FemVecX& out, bool with_f_el) const {
    const Vec3 g = options.gravity_m_per_s2;
    double applied_sq = 0.0;
    double elastic_sq = 0.0;
    for (std::size_t k = 0; k < free_node.size(); ++k) {
      const std::uint32_t node = free_node[k];
      Vec3 f = f_ext[node] + mass_free[k] * g;
      applied_sq += f.squaredNorm();
      if (with_f_el) {
        f += f_el[node];
        elastic_sq += f_el[node].squaredNorm();
      }
      out.segment<3>(static_cast<Eigen::Index>(3 * k)) = f;
    }
    return std::sqrt(applied_sq) + std::sqrt(elastic_sq);
  }

  // --- solves ---------------------------------------------------------------------------------

  void solve_double(const FemFactor& factor, FemVecX& y) {
    fem_solve_in_place<double>(symbolic, factor.values.data(), y.data(), solve_tmp.data());
  }

  /// out = Q·F⁻¹·Qᵀ·in (Q: the node frames, corotational), F a factor in float or double.
  void precondition(const FemFactor& factor, const FemVecX& in, FemVecX& out) {
    const std::size_t nf = free_node.size();
    if (corotational) {
      for (std::size_t k = 0; k < nf; ++k) {
        const auto i = static_cast<Eigen::Index>(3 * k);
        out.segment<3>(i).noalias() = node_r[k].transpose() * in.segment<3>(i);
      }
    } else {
      out = in;
    }
    if (factor.values.empty()) {
      pre_f = out.cast<float>();
      fem_solve_in_place<float>(symbolic, factor.values_f.data(), pre_f.data(), solve_tmp_f.data());
      out = pre_f.cast<double>();
    } else {
      solve_double(factor, out);
    }
    if (corotational) {
      for (std::size_t k = 0; k < nf; ++k) {
        const auto i = static_cast<Eigen::Index>(3 * k);
        const Vec3 t = out.segment<3>(i);
        out.segment<3>(i).noalias() = node_r[k] * t;
      }
    }
  }

  /// Preconditioned conjugate gradients on work_values·xs = b, from xs as given, until the
  /// residual is below the tolerance times max(‖b‖, force_scale).
  FemPcgResult pcg(const FemFactor& factor, const FemVecX& b, FemVecX& xs, int max_iterations,
                   double force_scale) {
    FemPcgResult out;
    const double tol = options.cg_relative_tolerance;
    const double b_norm = std::max(b.norm(), force_scale);
    if (!(b_norm > 0.0)) {
      xs.setZero();
      out.converged = std::isfinite(b_norm);
      return out;
    }
    fem_spmv(pattern, work_values, xs, prod);
    res = b - prod;
    double r_norm = res.norm();
    out.residual_relative = r_norm / b_norm;
    if (r_norm <= tol * b_norm) {
      return out;
    }
    precondition(factor, res, pre);
    dir = pre;
    double rz = res.dot(pre);
    for (int it = 1; it <= max_iterations; ++it) {
      fem_spmv(pattern, work_values, dir, prod);
      const double pq = dir.dot(prod);
      if (!(pq > 0.0)) {  // breakdown (an indefinite matrix: badly inverted elements)
        out.iterations = it;
        out.converged = false;
        return out;
      }
      const double alpha = rz / pq;
      xs += alpha * dir;
      res -= alpha * prod;
      r_norm = res.norm();
      out.iterations = it;
      out.residual_relative = r_norm / b_norm;
      if (r_norm <= tol * b_norm) {
        return out;
      }
      precondition(factor, res, pre);
      const double rz_next = res.dot(pre);
      dir = pre + (rz_next / rz) * dir;
      rz = rz_next;
    }
    out.converged = false;
    return out;
  }

  static void accumulate(FemStepStats& stats, const FemPcgResult& r) {
    stats.cg_iterations += r.iterations;
    stats.residual_relative = r.residual_relative;
    stats.converged = stats.converged && r.converged;
  }

  /// x += Δ on the free nodes; false (nothing applied) when Δ is not finite.
  bool apply_displacement(const FemVecX& delta) {
    if (!std::isfinite(delta.squaredNorm())) {
      return false;
    }
    for (std::size_t k = 0; k < free_node.size(); ++k) {
      x[free_node[k]] += delta.segment<3>(static_cast<Eigen::Index>(3 * k));
    }
    return true;
  }

  void zero_velocities() {
    std::fill(vel.begin(), vel.end(), Vec3::Zero());
    vel_previous.setZero();
  }

  /// After velocities were set from outside: the warm start extrapolates nothing yet.
  void sync_previous_velocities() {
    for (std::size_t k = 0; k < free_node.size(); ++k) {
      vel_previous.segment<3>(static_cast<Eigen::Index>(3 * k)) = vel[free_node[k]];
    }
  }

  /// One quasi-static update: K_T·Δx = f_ext + f_g + f_el(x), x += Δx (linear: exact, direct).
  /// Corotational with `line_search`: x += α·Δx, α from a secant search for the minimum of the
  /// energy along Δx (the corotational force is the exact gradient of the corotated energy; K_R
  /// lacks the rotation's derivative, so under large rotations the plain step is too short: a
  /// cantilever bent by half its length took 190 fixed-point rounds to 1e-7, 25 with the search).
  FemPcgResult static_update(double& update_norm, bool line_search = false) {
    FemPcgResult r;
    if (corotational) {
      element_pass(FemPass::kStiffness, kFemStepPolarIterations);
      const double scale = gather_forces(rhs, true);
      sol.setZero();
      r = pcg(factor_k, rhs, sol, options.max_cg_iterations, scale);
      if (line_search && r.iterations > 0 && apply_displacement(sol)) {
        const double slope0 = -rhs.dot(sol);  // dΠ/dα at α = 0, < 0
        double alpha_prev = 0.0;
        double slope_prev = slope0;
        double alpha = 1.0;
        for (int k = 0; k < 4; ++k) {
          element_pass(FemPass::kForces, kFemStepPolarIterations);
          gather_forces(res, true);
          const double slope = -res.dot(sol);
          const double curvature = (slope - slope_prev) / (alpha - alpha_prev);
          if (std::abs(slope) <= 1e-3 * std::abs(slope0) || !(curvature > 0.0)) {
            break;
          }
          const double next = std::clamp(alpha - slope / curvature, 0.05, 10.0);
          prod = (next - alpha) * sol;
          apply_displacement(prod);
          alpha_prev = alpha;
          slope_prev = slope;
          alpha = next;
        }
        update_norm = alpha * sol.norm();
        return r;
      }
    } else {
      linear_elastic_force(prod);
      gather_forces(rhs, false);
      sol = rhs + prod;
      solve_double(factor_k, sol);
    }
    if (!apply_displacement(sol)) {
      r.converged = false;
      update_norm = kInf;
      return r;
    }
    update_norm = sol.norm();
    return r;
  }

  FemStepStats step() {
    const auto t0 = FemClock::now();
    FemStepStats stats;
    const double dt = options.dt_s;
    if (!dynamic) {
      double update = 0.0;
      const int rounds = corotational ? options.quasi_static_iterations : 1;
      for (int k = 0; k < rounds; ++k) {
        const FemPcgResult r = static_update(update);
        accumulate(stats, r);
        if (corotational && r.iterations == 0 && r.converged) {
          break;  // in equilibrium to the tolerance: further rounds change nothing
        }
      }
      zero_velocities();
    } else {
      // (M + dt·C + dt²·K)·v₁ = M·v₀ + dt·(f_ext + f_g + f_el(x₀)), x₁ = x₀ + dt·v₁.
      double scale = 0.0;
      if (corotational) {
        element_pass(FemPass::kDynamic, kFemStepPolarIterations);
        scale = gather_forces(rhs, true);
      } else {
        linear_elastic_force(prod);
        gather_forces(rhs, false);
        rhs += prod;
      }
      rhs *= dt;
      double momentum_sq = 0.0;
      for (std::size_t k = 0; k < free_node.size(); ++k) {
        const auto i = static_cast<Eigen::Index>(3 * k);
        sol.segment<3>(i) = vel[free_node[k]];
        rhs.segment<3>(i) += mass_free[k] * sol.segment<3>(i);
        momentum_sq += mass_free[k] * mass_free[k] * sol.segment<3>(i).squaredNorm();
      }
      if (corotational) {
        // Warm start: v₀ extrapolated, 2·v₀ − v₋₁ (10 % fewer CG iterations than v₀ alone under
        // a varying load).
        pre = sol;
        sol = 2.0 * sol - vel_previous;
        vel_previous = pre;
        accumulate(stats, pcg(factor_a, rhs, sol, options.max_cg_iterations,
                              std::sqrt(momentum_sq) + dt * scale));
      } else {
        sol = rhs;
        solve_double(factor_a, sol);
      }
      if (std::isfinite(sol.squaredNorm())) {
        for (std::size_t k = 0; k < free_node.size(); ++k) {
          const std::uint32_t node = free_node[k];
          vel[node] = sol.segment<3>(static_cast<Eigen::Index>(3 * k));
          x[node] += dt * vel[node];
        }
      } else {
        stats.converged = false;
      }
    }
    stats.solve_ms = fem_ms_since(t0);
    return stats;
  }

  FemStepStats solve_static() {
    const auto t0 = FemClock::now();
    FemStepStats stats;
    zero_velocities();
    if (!corotational) {
      double update = 0.0;
      accumulate(stats, static_update(update));
    } else {
      // Fixed point on the rotations: stop when the update is below 100× the CG tolerance of
      // the displacement (the solves are only that accurate).
      bool done = false;
      for (int k = 0; k < kFemMaxStaticIterations && !done; ++k) {
        double update = 0.0;
        const FemPcgResult r = static_update(update, true);
        accumulate(stats, r);
        if (r.iterations == 0 && r.converged) {  // already in equilibrium to the tolerance
          done = true;
          break;
        }
        double displacement = 0.0;
        for (const std::uint32_t node : free_node) {
          displacement += (x[node] - mesh.nodes[node]).squaredNorm();
        }
        const double scale = std::sqrt(displacement) + 1e-300;
        done = update <= 100.0 * options.cg_relative_tolerance * scale;
      }
      stats.converged = stats.converged && done;
    }
    stats.solve_ms = fem_ms_since(t0);
    return stats;
  }

  void refresh_rotations_after_jump() {
    if (corotational) {
      // Converge the warm starts from wherever they were (queries do the same on their own).
      element_pass(FemPass::kForces, kFemQueryPolarIterations, kFemPolarTolerance);
    }
    update_fixed_coupling();
  }

  // --- contact ---------------------------------------------------------------------------------

  /// Penalty contact with a sphere as the minimum of Π(x) = elastic + load potential +
  /// Σ ½·k·max(0, r − |xᵢ − c|)² over the free boundary nodes: Newton steps (the springs of the
  /// nodes inside, frozen normals, tangent k·n·nᵀ) with an exact line search on Π along each
  /// step. Without the line search the active set oscillates (all of a geometric overlap held,
  /// most of it then pulling, dropped, the surface springing back through the sphere...).
  FemSphereContactResult sphere_contact(const Vec3& center, double radius, double penalty) {
    if (!fem_finite(center) || !std::isfinite(radius) || radius <= 0.0 || !std::isfinite(penalty) ||
        penalty <= 0.0) {
      fail(
          "solve_static_sphere_contact: expected a finite centre, a radius > 0 m and a "
          "penalty > 0 N/m, got radius " +
          fem_number(radius) + ", penalty " + fem_number(penalty));
    }
    FemSphereContactResult result;
    zero_velocities();
    const std::size_t nb = boundary_free.size();
    const auto inside = [&](std::size_t b) {
      return (x[boundary_free[b]] - center).norm() < radius ? char{1} : char{0};
    };
    std::vector<char> active(nb, 0);
    std::vector<char> factored_with(nb, 0);
    std::vector<Vec3> normal(nb, Vec3::UnitZ());
    for (std::size_t b = 0; b < nb; ++b) {
      active[b] = inside(b);
    }
    std::vector<double> contact_values;
    FemVecX elastic_rhs(rhs.size());
    bool have_factor = false;
    const double tol_update = 1e-7 * radius;
    for (int round = 1; round <= kFemMaxContactRounds; ++round) {
      result.active_set_iterations = round;
      // Tangent stiffness and the elastic + applied forces at x.
      double scale = 0.0;
      if (corotational) {
        element_pass(FemPass::kStiffness, kFemStepPolarIterations);
        scale = gather_forces(rhs, true);
      } else {
        work_values = k_values;
        linear_elastic_force(prod);
        scale = gather_forces(rhs, false) + prod.norm();
        rhs += prod;
      }
      elastic_rhs = rhs;
      // The springs of the active nodes: force k·(r − n·(x − c))·n, tangent k·n·nᵀ.
      std::size_t changed = 0;
      std::size_t active_count = 0;
      for (std::size_t b = 0; b < nb; ++b) {
        changed += active[b] != factored_with[b] ? 1U : 0U;
        if (!active[b]) {
          continue;
        }
        ++active_count;
        const std::uint32_t node = boundary_free[b];
        const Vec3 d = x[node] - center;
        normal[b] = d.norm() > 1e-12 * radius ? Vec3(d.normalized()) : Vec3::UnitZ();
        const Vec3& n = normal[b];
        const std::int32_t fi = free_index[node];
        Eigen::Map<Mat3>(work_values.data() + 9 * fem_sz(pattern.start[fem_sz(fi)])) +=
            penalty * n * n.transpose();
        const Vec3 spring = penalty * (radius - n.dot(d)) * n;
        rhs.segment<3>(Eigen::Index{3} * fi) += spring;
        scale += spring.norm();
      }
      // Preconditioner: K + the springs (in the node frames), factored for the first active set
      // and again only when much of it changed: a few changed nodes are a low-rank change, which
      // CG absorbs in about one iteration each, far cheaper than a factorisation.
      if (!have_factor || changed > std::max<std::size_t>(24, active_count / 4)) {
        contact_values = k_values;
        for (std::size_t b = 0; b < nb; ++b) {
          factored_with[b] = active[b];
          if (!active[b]) {
            continue;
          }
          const std::int32_t fi = free_index[boundary_free[b]];
          const Vec3 n =
              corotational ? Vec3(node_r[fem_sz(fi)].transpose() * normal[b]) : normal[b];
          Eigen::Map<Mat3>(contact_values.data() + 9 * fem_sz(pattern.start[fem_sz(fi)])) +=
              penalty * n * n.transpose();
        }
        factorize_into(contact_values, factor_contact, true, false, "the contact system");
        have_factor = true;
      }
      sol.setZero();
      const FemPcgResult r =
          pcg(factor_contact, rhs, sol, std::max(options.max_cg_iterations, 1000), scale);
      if (!std::isfinite(sol.squaredNorm())) {
        result.converged = false;
        break;
      }
      // Line search: φ(α) = Π(x + α·Δx); φ'(α) = −f·Δx + α·ΔxᵀK_TΔx + Σ springs' terms, with the
      // elastic part quadratic (exact for the linear model). Bisection on φ' in (0, 1].
      fem_spmv(pattern, work_values, sol, prod);
      double curvature = sol.dot(prod);
      for (std::size_t b = 0; b < nb; ++b) {
        if (active[b]) {
          const std::int32_t fi = free_index[boundary_free[b]];
          const double dn = normal[b].dot(sol.segment<3>(Eigen::Index{3} * fi));
          curvature -= penalty * dn * dn;
        }
      }
      const double slope0 = -elastic_rhs.dot(sol);
      const auto dphi = [&](double alpha) {
        double g = slope0 + alpha * curvature;
        for (std::size_t b = 0; b < nb; ++b) {
          const std::int32_t fi = free_index[boundary_free[b]];
          const Vec3 dx = sol.segment<3>(Eigen::Index{3} * fi);
          const Vec3 d = x[boundary_free[b]] + alpha * dx - center;
          const double dist = d.norm();
          if (dist < radius && dist > 0.0) {
            g -= penalty * (radius - dist) * d.dot(dx) / dist;
          }
        }
        return g;
      };
      double alpha = 1.0;
      if (dphi(1.0) > 0.0) {
        double lo = 0.0;
        double hi = 1.0;
        for (int k = 0; k < 40; ++k) {
          const double mid = 0.5 * (lo + hi);
          (dphi(mid) > 0.0 ? hi : lo) = mid;
        }
        alpha = std::max(0.5 * (lo + hi), 1e-3);
      }
      sol *= alpha;
      apply_displacement(sol);
      const double update = sol.lpNorm<Eigen::Infinity>();
      // The next active set: the nodes inside the sphere now.
      bool set_changed = false;
      for (std::size_t b = 0; b < nb; ++b) {
        const char now = inside(b);
        set_changed = set_changed || now != active[b];
        active[b] = now;
      }
      if (!set_changed && update <= tol_update && r.converged) {
        result.converged = true;
        break;
      }
    }
    // The springs' forces at the equilibrium found; the sphere feels the opposite.
    for (std::size_t b = 0; b < nb; ++b) {
      const Vec3 d = x[boundary_free[b]] - center;
      const double depth = radius - d.norm();
      if (depth > 0.0 && d.norm() > 0.0) {
        result.force_on_sphere_n -= penalty * depth * d.normalized();
        ++result.contact_nodes;
      }
    }
    refresh_rotations_after_jump();
    return result;
  }

  double compliance(std::span<const FemNodeWeight> point, const Vec3& n_in) {
    if (!fem_finite(n_in)) {
      return 0.0;
    }
    sol.setZero();
    bool any = false;
    for (const FemNodeWeight& w : point) {
      if (w.node >= mesh.node_count() || !std::isfinite(w.weight)) {
        continue;
      }
      const std::int32_t fi = free_index[w.node];
      if (fi < 0) {
        continue;
      }
      Vec3 n = n_in;
      if (corotational) {  // into the node's frame: the average of its tets' rotations
        Mat3 sum = Mat3::Zero();
        for (std::uint32_t p = node_tet_start[w.node]; p < node_tet_start[w.node + 1]; ++p) {
          const std::uint32_t t = node_tets[p];
          sum += query_rotation(t, deformation_gradient(elements[t], x));
        }
        Quat q = element_q[node_tets[node_tet_start[w.node]]];
        n = fem_extract_rotation(sum, q, kFemQueryPolarIterations, kFemPolarTolerance).transpose() *
            n_in;
      }
      sol.segment<3>(Eigen::Index{3} * fi) += w.weight * n;
      any = true;
    }
    if (!any) {
      return 0.0;
    }
    rhs = sol;
    solve_double(factor_k, sol);
    return rhs.dot(sol);
  }

  // --- queries -------------------------------------------------------------------------------

  /// Per element: rotation and element-frame strain at the current positions.
  void element_strain(std::size_t e, Mat3& r, Mat3& eps) const {
    const Mat3 f = deformation_gradient(elements[e], x);
    r = query_rotation(e, f);
    eps = strain_of(r.transpose() * f);
  }
};

// ---------------------------------------------------------------------------------------------

FemBody::FemBody(TetMesh mesh, const std::vector<FemRegionMaterial>& materials,
                 std::vector<std::uint32_t> fixed_nodes, const FemOptions& options,
                 std::string_view source)
    : impl_(std::make_unique<Impl>(std::move(mesh), materials, std::move(fixed_nodes), options,
                                   source)) {}

FemBody::~FemBody() = default;
FemBody::FemBody(FemBody&&) noexcept = default;
FemBody& FemBody::operator=(FemBody&&) noexcept = default;

const TetMesh& FemBody::rest_mesh() const {
  return impl_->mesh;
}
const FemOptions& FemBody::options() const {
  return impl_->options;
}
std::size_t FemBody::node_count() const {
  return impl_->mesh.node_count();
}
std::size_t FemBody::tet_count() const {
  return impl_->mesh.tet_count();
}

bool FemBody::is_fixed(std::uint32_t node) const {
  return std::binary_search(impl_->fixed.begin(), impl_->fixed.end(), node);
}

const std::vector<std::uint32_t>& FemBody::fixed_nodes() const {
  return impl_->fixed;
}
const std::vector<Vec3>& FemBody::positions() const {
  return impl_->x;
}
const std::vector<Vec3>& FemBody::velocities() const {
  return impl_->vel;
}

Vec3 FemBody::displacement(std::uint32_t node) const {
  if (node >= impl_->mesh.node_count()) {
    return Vec3::Zero();
  }
  return impl_->x[node] - impl_->mesh.nodes[node];
}

void FemBody::set_loads(std::span<const FemNodeForce> loads) {
  Impl& m = *impl_;
  std::fill(m.f_ext.begin(), m.f_ext.end(), Vec3::Zero());
  for (const FemNodeForce& load : loads) {
    if (load.node >= m.mesh.node_count() || !fem_finite(load.force_n)) {
      ++m.rejected;
      continue;
    }
    if (m.free_index[load.node] >= 0) {
      m.f_ext[load.node] += load.force_n;
    }
  }
}

std::size_t FemBody::rejected_loads() const {
  return impl_->rejected;
}

void FemBody::set_fixed_positions(std::span<const Vec3> positions) {
  Impl& m = *impl_;
  if (positions.size() != m.fixed.size()) {
    m.fail("set_fixed_positions: expected " + std::to_string(m.fixed.size()) +
           " positions (one per fixed node), got " + std::to_string(positions.size()));
  }
  for (const Vec3& p : positions) {
    if (!fem_finite(p)) {
      m.fail("set_fixed_positions: a position is not finite");
    }
  }
  for (std::size_t k = 0; k < m.fixed.size(); ++k) {
    m.x[m.fixed[k]] = positions[k];
  }
  m.update_fixed_coupling();
}

void FemBody::set_state(std::span<const Vec3> positions, std::span<const Vec3> velocities) {
  Impl& m = *impl_;
  const std::size_t n = m.mesh.node_count();
  if (positions.size() != n || (!velocities.empty() && velocities.size() != n)) {
    m.fail("set_state: expected " + std::to_string(n) + " positions and 0 or " + std::to_string(n) +
           " velocities, got " + std::to_string(positions.size()) + " and " +
           std::to_string(velocities.size()));
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!fem_finite(positions[i]) || (!velocities.empty() && !fem_finite(velocities[i]))) {
      m.fail("set_state: node " + std::to_string(i) + " has a non-finite position or velocity");
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    m.x[i] = positions[i];
    m.vel[i] = velocities.empty() || m.free_index[i] < 0 ? Vec3::Zero() : velocities[i];
  }
  m.sync_previous_velocities();
  m.refresh_rotations_after_jump();
}

FemStepStats FemBody::step() {
  return impl_->step();
}
FemStepStats FemBody::solve_static() {
  return impl_->solve_static();
}

void FemBody::reset() {
  Impl& m = *impl_;
  std::copy(m.mesh.nodes.begin(), m.mesh.nodes.end(), m.x.begin());
  std::fill(m.vel.begin(), m.vel.end(), Vec3::Zero());
  std::fill(m.f_ext.begin(), m.f_ext.end(), Vec3::Zero());
  std::fill(m.element_q.begin(), m.element_q.end(), Quat::Identity());
  std::fill(m.node_r.begin(), m.node_r.end(), Mat3::Identity());
  m.coupling.setZero();
  m.vel_previous.setZero();
}

double FemBody::compliance_along(std::span<const FemNodeWeight> point, const Vec3& n) {
  return impl_->compliance(point, n);
}

FemSphereContactResult FemBody::solve_static_sphere_contact(const Vec3& center, double radius_m,
                                                            double penalty_n_per_m) {
  return impl_->sphere_contact(center, radius_m, penalty_n_per_m);
}

void FemBody::elastic_forces(std::vector<Vec3>& out) const {
  const Impl& m = *impl_;
  out.assign(m.mesh.node_count(), Vec3::Zero());
  for (std::size_t e = 0; e < m.elements.size(); ++e) {
    const FemElement& el = m.elements[e];
    Mat3 r;
    Mat3 eps;
    m.element_strain(e, r, eps);
    const Mat3 forces = -(r * Impl::stress_times_volume(el, eps)) * el.dm_inv.transpose();
    out[el.node[1]] += forces.col(0);
    out[el.node[2]] += forces.col(1);
    out[el.node[3]] += forces.col(2);
    out[el.node[0]] -= forces.col(0) + forces.col(1) + forces.col(2);
  }
}

void FemBody::von_mises_pa(std::vector<double>& out) const {
  const Impl& m = *impl_;
  out.resize(m.elements.size());
  for (std::size_t e = 0; e < m.elements.size(); ++e) {
    const FemElement& el = m.elements[e];
    Mat3 r;
    Mat3 eps;
    m.element_strain(e, r, eps);
    const Mat3 s = Impl::stress_times_volume(el, eps) / el.volume_m3;
    const double d01 = s(0, 0) - s(1, 1);
    const double d12 = s(1, 1) - s(2, 2);
    const double d20 = s(2, 2) - s(0, 0);
    out[el.tet] = std::sqrt(0.5 * (d01 * d01 + d12 * d12 + d20 * d20) +
                            3.0 * (s(0, 1) * s(0, 1) + s(1, 2) * s(1, 2) + s(2, 0) * s(2, 0)));
  }
}

void FemBody::element_stress_pa(std::vector<Mat3>& out) const {
  const Impl& m = *impl_;
  out.resize(m.elements.size());
  for (std::size_t e = 0; e < m.elements.size(); ++e) {
    const FemElement& el = m.elements[e];
    Mat3 r;
    Mat3 eps;
    m.element_strain(e, r, eps);
    out[el.tet] = r * (Impl::stress_times_volume(el, eps) / el.volume_m3) * r.transpose();
  }
}

double FemBody::elastic_energy_j() const {
  const Impl& m = *impl_;
  double energy = 0.0;
  for (std::size_t e = 0; e < m.elements.size(); ++e) {
    Mat3 r;
    Mat3 eps;
    m.element_strain(e, r, eps);
    energy += 0.5 * (Impl::stress_times_volume(m.elements[e], eps).cwiseProduct(eps)).sum();
  }
  return energy;
}

double FemBody::kinetic_energy_j() const {
  const Impl& m = *impl_;
  double energy = 0.0;
  for (std::size_t i = 0; i < m.x.size(); ++i) {
    energy += 0.5 * m.node_mass_kg[i] * m.vel[i].squaredNorm();
  }
  return energy;
}

double FemBody::total_mass_kg() const {
  return impl_->total_mass_kg;
}

std::size_t FemBody::factor_nonzeros() const {
  return impl_->symbolic.nonzeros;
}

std::size_t FemBody::factor_memory_bytes() const {
  const Impl& m = *impl_;
  return m.factor_a.bytes() + m.factor_k.bytes() + m.factor_contact.bytes() +
         m.symbolic.index_bytes();
}

double FemBody::factorisation_ms() const {
  return impl_->factor_ms;
}
std::size_t FemBody::unknowns() const {
  return 3 * impl_->free_node.size();
}

}  // namespace hapsim
