// Disjoint sets over the indices 0..n-1 (union-find with path halving): the connected pieces of
// a mesh, joined through shared vertices or nodes.
#pragma once

#include <cstdint>
#include <numeric>
#include <vector>

namespace hapsim {

class DisjointSets {
 public:
  explicit DisjointSets(std::size_t count) : parent_(count) {
    std::iota(parent_.begin(), parent_.end(), std::uint32_t{0});
  }
  /// The representative of `v`'s set. Precondition: v < count.
  [[nodiscard]] std::uint32_t find(std::uint32_t v) {
    while (parent_[v] != v) {
      parent_[v] = parent_[parent_[v]];
      v = parent_[v];
    }
    return v;
  }
  /// Joins the sets of `a` and `b`.
  void unite(std::uint32_t a, std::uint32_t b) { parent_[find(b)] = find(a); }

 private:
  std::vector<std::uint32_t> parent_;
};

}  // namespace hapsim
