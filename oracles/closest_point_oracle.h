// Reference implementations of closest-point queries from other libraries (CGAL, FCL, Embree),
// used ONLY by tests and benchmarks to check and measure hapsim's own contact code.
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/geometry/triangle_mesh.h"

#include <memory>
#include <string>
#include <vector>

namespace hapsim::oracle {

struct OracleAnswer {
  Vec3 point = Vec3::Zero();  // closest point on the surface
  double distance = 0.0;      // unsigned
  std::uint32_t triangle = kNoTriangle;
};

class ClosestPointOracle {
 public:
  virtual ~ClosestPointOracle() = default;
  /// Row name in benchmark tables: "cgal", "cgal-hint", "fcl", "embree".
  [[nodiscard]] virtual std::string name() const = 0;
  [[nodiscard]] virtual OracleAnswer closest(const Vec3& p) = 0;
  [[nodiscard]] virtual double build_ms() const = 0;
  /// Best estimate of the structure's memory (mesh copy included where the library keeps one).
  [[nodiscard]] virtual std::size_t memory_bytes() const = 0;
};

/// Oracles available in this build ("cgal", "cgal-hint", "fcl", "embree").
std::vector<std::string> available_oracles();
/// Builds one by name over `mesh`; nullptr if not built in.
std::unique_ptr<ClosestPointOracle> make_oracle(const std::string& name, const TriangleMesh& mesh);

}  // namespace hapsim::oracle
