#include "hapsim/scene/fem_reader.h"

#include <cmath>
#include <set>
#include <string>

namespace hapsim {

namespace {

using Json = JsonReader::Json;

FemMaterial fem_region_material(const JsonReader& r, const Json& m, const std::string& p) {
  r.allow_keys(m, p,
               {"region", "name", "youngs_modulus_pa", "poisson_ratio", "density_kg_per_m3",
                "rayleigh_mass_per_s", "rayleigh_stiffness_s", "nonlinear_modulus_pa", "source"});
  for (const char* key : {"name", "source"}) {
    if (m.contains(key)) {
      (void)r.string(m[key], JsonReader::at(p, key), "text");  // documentation only
    }
  }
  FemMaterial out;
  out.youngs_modulus_pa =
      r.number_in(m, p, "youngs_modulus_pa", out.youngs_modulus_pa, 0.0, 1e12, "Pa", true);
  // ν = 0.5 is incompressible: linear tetrahedra lock and the stiffness is singular.
  out.poisson_ratio = r.number_in(m, p, "poisson_ratio", out.poisson_ratio, 0.0, 0.499, "");
  out.density_kg_per_m3 =
      r.number_in(m, p, "density_kg_per_m3", out.density_kg_per_m3, 0.0, 1e5, "kg/m^3", true);
  out.rayleigh_mass_per_s = r.number_in(m, p, "rayleigh_mass_per_s", 0.0, 0.0, 1e4, "1/s");
  out.rayleigh_stiffness_s = r.number_in(m, p, "rayleigh_stiffness_s", 0.0, 0.0, 10.0, "s");
  out.nonlinear_modulus_pa = r.number_in(m, p, "nonlinear_modulus_pa", 0.0, 0.0, 1e12, "Pa");
  return out;
}

}  // namespace

FemBodyDescription read_fem_settings(const JsonReader& r, const Json* j, const std::string& ptr,
                                     const TetMesh& tets, bool embedded_surface,
                                     std::string source) {
  FemBodyDescription d;
  d.tets = tets;
  d.embedded_surface = embedded_surface;
  d.source = std::move(source);
  const Json empty = Json::object();
  const Json& f = j != nullptr ? r.object(*j, ptr, "FEM settings") : empty;
  r.allow_keys(
      f, ptr,
      {"elasticity", "integration", "dt_s", "regions", "fixed", "gravity_m_per_s2",
       "max_cg_iterations", "cg_relative_tolerance", "contact_patch_radius_m", "contact_margin_m"});
  if (f.contains("elasticity")) {
    d.options.elasticity = r.one_of(f["elasticity"], JsonReader::at(ptr, "elasticity"),
                                    {"linear", "corotational"}) == "linear"
                               ? FemElasticity::kLinear
                               : FemElasticity::kCorotational;
  }
  if (f.contains("integration")) {
    d.options.integration = r.one_of(f["integration"], JsonReader::at(ptr, "integration"),
                                     {"backward_euler", "quasi_static"}) == "quasi_static"
                                ? FemIntegration::kQuasiStatic
                                : FemIntegration::kBackwardEuler;
  }
  d.options.dt_s = r.number_in(f, ptr, "dt_s", d.options.dt_s, 1e-4, 0.1, "s");
  if (f.contains("gravity_m_per_s2")) {
    d.options.gravity_m_per_s2 =
        r.vec3(f["gravity_m_per_s2"], JsonReader::at(ptr, "gravity_m_per_s2"), "m/s^2");
  }
  const double cg_iterations =
      r.number_in(f, ptr, "max_cg_iterations", d.options.max_cg_iterations, 1.0, 10000.0, "");
  if (cg_iterations != std::floor(cg_iterations)) {
    r.fail(JsonReader::at(ptr, "max_cg_iterations"), "expected a whole number of iterations");
  }
  d.options.max_cg_iterations = static_cast<int>(cg_iterations);
  d.options.cg_relative_tolerance = r.number_in(
      f, ptr, "cg_relative_tolerance", d.options.cg_relative_tolerance, 0.0, 0.1, "", true);
  d.contact_patch_radius_m =
      r.number_in(f, ptr, "contact_patch_radius_m", d.contact_patch_radius_m, 0.0, 0.1, "m", true);
  d.contact_margin_m =
      r.number_in(f, ptr, "contact_margin_m", d.contact_margin_m, 0.0, 0.2, "m", true);

  // Materials per region; every region the mesh has needs one.
  std::set<std::int32_t> mesh_regions;
  for (std::size_t t = 0; t < tets.tet_count(); ++t) {
    mesh_regions.insert(tets.region(t));
  }
  if (f.contains("regions")) {
    const std::string rp = JsonReader::at(ptr, "regions");
    const Json& regions = r.array(f["regions"], rp, "materials per region");
    std::set<std::int32_t> seen;
    for (std::size_t i = 0; i < regions.size(); ++i) {
      const std::string p = JsonReader::at(rp, i);
      const Json& m = r.object(regions[i], p, "a region's material");
      const double id =
          m.contains("region") ? r.number(m["region"], JsonReader::at(p, "region"), "") : 0.0;
      if (id != std::floor(id) || std::abs(id) > 1e9) {
        r.fail(JsonReader::at(p, "region"), "expected a whole region number");
      }
      const auto region = static_cast<std::int32_t>(id);
      if (!seen.insert(region).second) {
        r.fail(JsonReader::at(p, "region"),
               "region " + std::to_string(region) + " has a material already");
      }
      if (mesh_regions.count(region) == 0) {
        r.fail(JsonReader::at(p, "region"), "the mesh has no region " + std::to_string(region) +
                                                " (a material for nothing is likely a typo)");
      }
      d.materials.push_back({region, fem_region_material(r, m, p)});
    }
  } else {
    for (const std::int32_t region : mesh_regions) {
      d.materials.push_back({region, FemMaterial{}});
    }
  }
  for (const std::int32_t region : mesh_regions) {
    bool found = false;
    for (const FemRegionMaterial& m : d.materials) {
      found = found || m.region == region;
    }
    if (!found) {
      r.fail(JsonReader::at(ptr, "regions"),
             "the mesh has region " + std::to_string(region) + " and no material is given for it");
    }
  }

  // How it is held.
  if (!f.contains("fixed")) {
    r.fail(j != nullptr ? ptr : ptr.substr(0, ptr.rfind('/')),
           "a FEM body needs \"fem\": {\"fixed\": ...}: nodes, a plane (below_z_m) or "
           "attached_to a body");
  }
  const std::string fp = JsonReader::at(ptr, "fixed");
  const Json& fixed = r.object(f["fixed"], fp, "fixed nodes");
  r.allow_keys(fixed, fp, {"below_z_m", "nodes", "attached_to"});
  if (fixed.contains("below_z_m")) {
    d.fixed_below_z_m = r.number(fixed["below_z_m"], JsonReader::at(fp, "below_z_m"), "m");
    const double lowest = tets.bounds().min().z();
    if (*d.fixed_below_z_m < lowest) {
      r.fail(JsonReader::at(fp, "below_z_m"),
             "no node is that low: the volume's lowest node is at z = " + std::to_string(lowest) +
                 " m (body frame)");
    }
  }
  if (fixed.contains("nodes")) {
    const std::string np = JsonReader::at(fp, "nodes");
    const Json& nodes = r.array(fixed["nodes"], np, "node indices");
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      const double n = r.number(nodes[i], JsonReader::at(np, i), "");
      if (!(n >= 0.0) || n != std::floor(n) || n >= static_cast<double>(tets.node_count())) {
        r.fail(JsonReader::at(np, i),
               "expected a node index in 0.." + std::to_string(tets.node_count() - 1));
      }
      d.fixed_nodes.push_back(static_cast<std::uint32_t>(n));
    }
  }
  if (fixed.contains("attached_to")) {
    const std::string ap = JsonReader::at(fp, "attached_to");
    const Json& list = r.array(fixed["attached_to"], ap, "bodies the volume is attached to");
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string p = JsonReader::at(ap, i);
      const Json& a = r.object(list[i], p, "an attachment");
      r.allow_keys(a, p, {"body", "segment", "within_m"});
      FemAttachment at;
      at.body = r.nonempty_string(r.required(a, p, "body"), JsonReader::at(p, "body"), "a body");
      if (a.contains("segment")) {
        at.segment = r.string(a["segment"], JsonReader::at(p, "segment"), "a segment");
      }
      at.within_m = r.number_in(a, p, "within_m", at.within_m, 0.0, 0.1, "m");
      at.where = r.file().string() + ":" + JsonReader::at(p, "body");
      d.attached_to.push_back(std::move(at));
    }
  }
  if (!d.fixed_below_z_m && d.fixed_nodes.empty() && d.attached_to.empty()) {
    r.fail(fp, "expected at least one of below_z_m, nodes or attached_to");
  }
  return d;
}

}  // namespace hapsim
