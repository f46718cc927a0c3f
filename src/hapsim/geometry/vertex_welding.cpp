#include "hapsim/geometry/vertex_welding.h"

#include <array>
#include <bit>
#include <cmath>
#include <unordered_map>
#include <vector>

namespace hapsim {
namespace {

struct KeyHash {
  std::size_t operator()(const std::array<std::uint64_t, 3>& k) const noexcept {
    // splitmix-style mixing; coordinates of nearby vertices differ only in low bits.
    std::uint64_t h = 0x9e3779b97f4a7c15ull;
    for (std::uint64_t x : k) {
      h ^= x + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
      h = (h ^ (h >> 30)) * 0xbf58476d1ce4e5b9ull;
      h = (h ^ (h >> 27)) * 0x94d049bb133111ebull;
      h ^= h >> 31;
    }
    return static_cast<std::size_t>(h);
  }
};

using Key = std::array<std::uint64_t, 3>;

bool is_finite(const Vec3& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

// Bit pattern as the key: equal doubles (and identical NaN/inf spellings, which a file repeats
// for every face corner once an importer de-indexes it) share one vertex.
Key exact_key(const Vec3& v) {
  // + 0.0 turns −0 into +0 so both spellings of zero weld.
  return {std::bit_cast<std::uint64_t>(v.x() + 0.0), std::bit_cast<std::uint64_t>(v.y() + 0.0),
          std::bit_cast<std::uint64_t>(v.z() + 0.0)};
}

}  // namespace

std::size_t weld_vertices(TriangleMesh& mesh, double tolerance_m) {
  const std::size_t nv = mesh.vertices.size();
  std::vector<std::uint32_t> remap(nv);
  std::vector<Vec3> kept;
  kept.reserve(nv);
  const auto keep = [&](std::size_t v) {
    remap[v] = static_cast<std::uint32_t>(kept.size());
    kept.push_back(mesh.vertices[v]);
  };

  const bool exact = !(tolerance_m > 0.0) || !std::isfinite(tolerance_m);
  if (exact) {
    std::unordered_map<Key, std::uint32_t, KeyHash> first;
    first.reserve(nv);
    for (std::size_t v = 0; v < nv; ++v) {
      const auto [it, inserted] =
          first.try_emplace(exact_key(mesh.vertices[v]), static_cast<std::uint32_t>(kept.size()));
      if (inserted) {
        keep(v);
      } else {
        remap[v] = it->second;
      }
    }
  } else {
    // Hash grid with cells of the tolerance: a match can only be in the 27 surrounding cells.
    const double inv_cell = 1.0 / tolerance_m;
    const double tol2 = tolerance_m * tolerance_m;
    constexpr double kMaxCell = 4.0e18;  // beyond int64 range the grid is meaningless
    std::unordered_map<Key, std::vector<std::uint32_t>, KeyHash> grid;
    std::unordered_map<Key, std::uint32_t, KeyHash> off_grid;
    grid.reserve(nv);
    for (std::size_t v = 0; v < nv; ++v) {
      const Vec3& p = mesh.vertices[v];
      const Vec3 cell_f = (p * inv_cell).array().floor();
      if (!is_finite(p) || !(cell_f.cwiseAbs().maxCoeff() <= kMaxCell)) {
        // Off the grid (non-finite or astronomically far): bit-identical duplicates only.
        const auto [it, inserted] =
            off_grid.try_emplace(exact_key(p), static_cast<std::uint32_t>(kept.size()));
        if (inserted) {
          keep(v);
        } else {
          remap[v] = it->second;
        }
        continue;
      }
      const std::array<std::int64_t, 3> cell{static_cast<std::int64_t>(cell_f.x()),
                                             static_cast<std::int64_t>(cell_f.y()),
                                             static_cast<std::int64_t>(cell_f.z())};
      std::uint32_t match = kNoTriangle;
      for (int dx = -1; dx <= 1 && match == kNoTriangle; ++dx) {
        for (int dy = -1; dy <= 1 && match == kNoTriangle; ++dy) {
          for (int dz = -1; dz <= 1 && match == kNoTriangle; ++dz) {
            const Key k{static_cast<std::uint64_t>(cell[0] + dx),
                        static_cast<std::uint64_t>(cell[1] + dy),
                        static_cast<std::uint64_t>(cell[2] + dz)};
            const auto it = grid.find(k);
            if (it == grid.end()) {
              continue;
            }
            for (std::uint32_t rep : it->second) {
              if ((kept[rep] - p).squaredNorm() <= tol2) {
                match = rep;
                break;
              }
            }
          }
        }
      }
      if (match != kNoTriangle) {
        remap[v] = match;
      } else {
        grid[Key{static_cast<std::uint64_t>(cell[0]), static_cast<std::uint64_t>(cell[1]),
                 static_cast<std::uint64_t>(cell[2])}]
            .push_back(static_cast<std::uint32_t>(kept.size()));
        keep(v);
      }
    }
  }

  const std::size_t removed = nv - kept.size();
  if (removed == 0) {
    return 0;
  }
  for (TriangleIndices& t : mesh.triangles) {
    for (std::uint32_t& v : t) {
      if (v < nv) {
        v = remap[v];
      }
    }
  }
  mesh.vertices = std::move(kept);
  if (!mesh.vertex_normals.empty()) {
    // Bad indices would make the normal pass read out of bounds; drop normals instead.
    bool ok = true;
    for (const TriangleIndices& t : mesh.triangles) {
      ok = ok && t[0] < mesh.vertices.size() && t[1] < mesh.vertices.size() &&
           t[2] < mesh.vertices.size();
    }
    if (ok) {
      mesh.compute_vertex_normals();
    } else {
      mesh.vertex_normals.clear();
    }
  }
  return removed;
}

}  // namespace hapsim
