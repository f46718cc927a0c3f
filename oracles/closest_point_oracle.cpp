#include "oracles/closest_point_oracle.h"

#include "oracles/oracle_factories.h"

namespace hapsim::oracle {

std::vector<std::string> available_oracles() {
  std::vector<std::string> names;
#ifdef HAPSIM_HAVE_CGAL
  names.emplace_back("cgal");
  names.emplace_back("cgal-hint");
#endif
#ifdef HAPSIM_HAVE_FCL
  names.emplace_back("fcl");
#endif
#ifdef HAPSIM_HAVE_EMBREE
  names.emplace_back("embree");
#endif
  return names;
}

std::unique_ptr<ClosestPointOracle> make_oracle(const std::string& name, const TriangleMesh& mesh) {
#ifdef HAPSIM_HAVE_CGAL
  if (name == "cgal" || name == "cgal-hint") {
    return make_cgal_oracle(mesh, name == "cgal-hint");
  }
#endif
#ifdef HAPSIM_HAVE_FCL
  if (name == "fcl") {
    return make_fcl_oracle(mesh);
  }
#endif
#ifdef HAPSIM_HAVE_EMBREE
  if (name == "embree") {
    return make_embree_oracle(mesh);
  }
#endif
  (void)mesh;
  return nullptr;
}

}  // namespace hapsim::oracle
