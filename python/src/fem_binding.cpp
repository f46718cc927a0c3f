// FEM bodies and tet meshes from Python (docs/python.md#fem-bodies): hapsim.TetMesh (read from
// Gmsh, TetGen and VTK files, generated, or given as arrays) with its shape quality, and World's
// fem_* methods: a FEM body's nodes, tets, regions, fixed nodes, displacement and stresses as
// NumPy arrays (copies), and the coupling's figures.
//
// A FEM body's state belongs to the FEM side (world/fem_coupling.h: read only on its thread or
// while nothing steps). A World stepped from Python runs each FEM update inside the step that
// launches it (World::set_fem_deferred is never set here) on the calling thread, so between two
// calls of World.step nothing touches it and these reads are safe.
#include "arrays.h"
#include "bindings.h"

#include "hapsim/deform/fem_body.h"
#include "hapsim/geometry/tet_mesh.h"
#include "hapsim/geometry/tet_mesh_io.h"
#include "hapsim/runtime/session.h"
#include "hapsim/runtime/session_json.h"
#include "hapsim/world/fem_coupling.h"
#include "hapsim/world/world.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace hapsim::python {
namespace {

// hapsim.TetMesh: immutable once made; its arrays are views of it (they keep it alive).
struct PyTetMesh {
  TetMesh mesh;
  std::string source;
  // One region per tet (a mesh without regions: all 0), so `regions` is always (T,).
  std::vector<std::int32_t> regions;
};

std::unique_ptr<PyTetMesh> make_py_tet_mesh(TetMesh mesh, std::string source) {
  auto out = std::make_unique<PyTetMesh>();
  out->regions.resize(mesh.tet_count());
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    out->regions[t] = mesh.region(t);
  }
  out->mesh = std::move(mesh);
  out->source = std::move(source);
  return out;
}

// Integers as int64 (a null array for anything else: a float is not truncated to an index), so
// a negative or too large one is refused instead of wrapped.
py::array_t<std::int64_t, py::array::c_style> integer_array(const py::object& values) {
  using IndexArray = py::array_t<std::int64_t, py::array::c_style>;
  const py::array a = py::array::ensure(values);
  if (!a || (a.dtype().kind() != 'i' && a.dtype().kind() != 'u')) {
    return {};
  }
  return IndexArray::ensure(a);
}

// A tet mesh from arrays: nodes (N,3) metres, tets (T,4) node indices, regions (T,) or None.
// Not validated here (quality() and validate() say what is wrong with it).
std::unique_ptr<PyTetMesh> tet_mesh_from_arrays(const DoubleArray& nodes, const py::object& tets,
                                                const py::object& regions) {
  if (nodes.ndim() != 2 || nodes.shape(1) != 3) {
    throw Error("nodes", "expected an N×3 array of metres");
  }
  const auto t = integer_array(tets);
  if (!t || t.ndim() != 2 || t.shape(1) != 4) {
    throw Error("tets", "expected a T×4 array of integer node indices");
  }
  TetMesh mesh;
  const py::ssize_t n = nodes.shape(0);
  mesh.nodes.reserve(static_cast<std::size_t>(n));
  const double* p = nodes.data();
  for (py::ssize_t i = 0; i < n; ++i) {
    mesh.nodes.emplace_back(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
  }
  const std::int64_t* ti = t.data();
  mesh.tets.reserve(static_cast<std::size_t>(t.shape(0)));
  for (py::ssize_t e = 0; e < t.shape(0); ++e) {
    TetIndices tet{};
    for (std::size_t k = 0; k < 4; ++k) {
      const std::int64_t v = ti[4 * e + static_cast<py::ssize_t>(k)];
      if (v < 0 || v > static_cast<std::int64_t>(UINT32_MAX)) {
        throw Error("tets", "element " + std::to_string(e) + ": node index " + std::to_string(v) +
                                " is not a node number");
      }
      tet[k] = static_cast<std::uint32_t>(v);
    }
    mesh.tets.push_back(tet);
  }
  if (!regions.is_none()) {
    const auto r = integer_array(regions);
    if (!r || r.ndim() != 1 || r.shape(0) != t.shape(0)) {
      throw Error("regions",
                  "expected one integer region per tet (" + std::to_string(t.shape(0)) + ")");
    }
    mesh.regions.reserve(static_cast<std::size_t>(r.shape(0)));
    for (py::ssize_t e = 0; e < r.shape(0); ++e) {
      const std::int64_t v = r.at(e);
      if (v < INT32_MIN || v > INT32_MAX) {
        throw Error("regions", "element " + std::to_string(e) + ": region " + std::to_string(v) +
                                   " is out of the 32-bit range");
      }
      mesh.regions.push_back(static_cast<std::int32_t>(v));
    }
  }
  return make_py_tet_mesh(std::move(mesh), "tet mesh");
}

py::dict quality_dict(const TetMeshQuality& q) {
  py::dict out;
  out["tets"] = q.tets;
  out["nodes"] = q.nodes;
  out["min_dihedral_deg"] = q.min_dihedral_deg;
  out["max_dihedral_deg"] = q.max_dihedral_deg;
  out["max_aspect_ratio"] = q.max_aspect_ratio;
  out["min_volume_m3"] = q.min_volume_m3;
  out["total_volume_m3"] = q.total_volume_m3;
  out["inverted"] = q.inverted;
  out["degenerate"] = q.degenerate;
  out["components"] = q.components;
  out["unused_nodes"] = q.unused_nodes;
  out["out_of_range"] = q.out_of_range;
  out["non_finite"] = q.non_finite;
  return out;
}

template <class T, std::size_t N>
py::array_t<T> rows_view(const py::object& owner, const std::vector<std::array<T, N>>& rows) {
  return view<T>(owner, rows.empty() ? nullptr : rows.front().data(), rows.size(), N,
                 sizeof(std::array<T, N>));
}

py::array_t<double> nodes_view(const py::object& owner, const std::vector<Vec3>& nodes) {
  return view<double>(owner, nodes.empty() ? nullptr : nodes.front().data(), nodes.size(), 3,
                      sizeof(Vec3));
}

// One FEM body of a world: its coupling, its index among the FEM bodies, its world body.
struct FemRef {
  const FemCoupling* fem = nullptr;
  std::size_t index = 0;
  std::size_t body = 0;
  const FemBody& solver() const { return fem->body(index); }
};

std::string fem_body_list(const World& w) {
  const FemCoupling* fem = w.fem();
  if (fem == nullptr || fem->body_count() == 0) {
    return "the world has no FEM body";
  }
  std::string out;
  for (std::size_t i = 0; i < fem->body_count(); ++i) {
    const std::size_t b = fem->world_body(i);
    out += (out.empty() ? "" : ", ") + w.description().bodies[b].name + " (body " +
           std::to_string(b) + ")";
  }
  return "the world's FEM bodies: " + out;
}

// A FEM body by its name or its world body index (as body_pose and surface number bodies).
FemRef fem_ref(const World& w, const py::handle& body) {
  const auto& bodies = w.description().bodies;
  std::size_t b = 0;
  std::string named;
  if (py::isinstance<py::str>(body)) {
    named = body.cast<std::string>();
    b = bodies.size();
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      if (bodies[i].name == named) {
        b = i;
        break;
      }
    }
    if (b == bodies.size()) {
      throw Error("body", "no FEM body '" + named + "'; " + fem_body_list(w));
    }
  } else if (PyIndex_Check(body.ptr()) != 0 && !py::isinstance<py::bool_>(body)) {
    // An int, or a NumPy integer.
    const auto i = body.cast<long long>();
    if (i < 0 || static_cast<unsigned long long>(i) >= bodies.size()) {
      throw py::index_error("no body " + std::to_string(i));
    }
    b = static_cast<std::size_t>(i);
  } else {
    throw Error("body", "expected a body's name or index");
  }
  const FemCoupling* fem = w.fem();
  for (std::size_t i = 0; fem != nullptr && i < fem->body_count(); ++i) {
    if (fem->world_body(i) == b) {
      return {fem, i, b};
    }
  }
  throw Error("body", "body " + std::to_string(b) + " ('" + bodies[b].name +
                          "') is not a FEM body; " + fem_body_list(w));
}

// Per node, X·(a point in the body frame) (`points`) or R·(a vector) (`!points`), as (N,3).
py::array_t<double> world_rows(const std::vector<Vec3>& body_frame, const Iso3& X, bool points) {
  const auto n = static_cast<py::ssize_t>(body_frame.size());
  py::array_t<double> a({n, py::ssize_t{3}});
  double* o = a.mutable_data();
  for (py::ssize_t i = 0; i < n; ++i) {
    const Vec3& v = body_frame[static_cast<std::size_t>(i)];
    const Vec3 w = points ? Vec3(X * v) : Vec3(X.linear() * v);
    o[3 * i] = w.x();
    o[3 * i + 1] = w.y();
    o[3 * i + 2] = w.z();
  }
  return a;
}

py::dict fem_body_info(const World& w, const FemCoupling& fem, std::size_t i) {
  const FemBody& s = fem.body(i);
  py::dict out;
  out["name"] = w.description().bodies[fem.world_body(i)].name;
  out["body"] = fem.world_body(i);
  out["nodes"] = s.node_count();
  out["tets"] = s.tet_count();
  out["fixed_nodes"] = s.fixed_nodes().size();
  out["elasticity"] = std::string(to_string(s.options().elasticity));
  out["integration"] = std::string(to_string(s.options().integration));
  out["dt_s"] = s.options().dt_s;
  out["mass_kg"] = s.total_mass_kg();
  return out;
}

// The run's FEM figures (the "fem" object of `hapsim run --json`), or None without FEM bodies.
py::object fem_stats(const World& w) {
  const std::optional<FemSummary> s = fem_summary(w);
  if (!s) {
    return py::none();
  }
  // The very object `hapsim run --json` writes (one place builds it), as Python values.
  return py::module_::import("json").attr("loads")(fem_summary_json(*s).dump());
}

// Adds a method to the World class bind_world made (what class_::def does, by the class object:
// its C++ type is world_binding.cpp's own).
template <class F, class... Extra>
void def_world(const py::object& cls, const char* name, F&& f, const Extra&... extra) {
  py::cpp_function cf(std::forward<F>(f), py::name(name), py::is_method(cls),
                      py::sibling(py::getattr(cls, name, py::none())), extra...);
  cls.attr(name) = cf;
}

void bind_world_fem(py::module_& m) {
  const py::object cls = m.attr("World");
  def_world(
      cls, "fem_bodies",
      [](const py::object& self) {
        const World& w = world_of(self);
        py::list out;
        const FemCoupling* fem = w.fem();
        for (std::size_t i = 0; fem != nullptr && i < fem->body_count(); ++i) {
          out.append(fem_body_info(w, *fem, i));
        }
        return out;
      },
      "The world's FEM bodies, in order: per body a dict of name, body (its index among the "
      "world's bodies), nodes, tets, fixed_nodes, elasticity, integration, dt_s, mass_kg.");
  def_world(
      cls, "fem_node_positions",
      [](const py::object& self, const py::object& body) {
        const World& w = world_of(self);
        const FemRef r = fem_ref(w, body);
        return world_rows(r.solver().positions(), w.body_pose(r.body), true);
      },
      py::arg("body"),
      "(N,3) each node's position now, world frame, metres (a copy). body: its name or index.");
  def_world(
      cls, "fem_rest_nodes",
      [](const py::object& self, const py::object& body) {
        const World& w = world_of(self);
        const FemRef r = fem_ref(w, body);
        return world_rows(r.solver().rest_mesh().nodes, w.body_pose(r.body), true);
      },
      py::arg("body"), "(N,3) each node's rest position, world frame, metres (a copy).");
  def_world(
      cls, "fem_displacement",
      [](const py::object& self, const py::object& body) {
        const World& w = world_of(self);
        const FemRef r = fem_ref(w, body);
        const FemBody& s = r.solver();
        std::vector<Vec3> u(s.node_count());
        for (std::size_t i = 0; i < u.size(); ++i) {
          u[i] = s.displacement(static_cast<std::uint32_t>(i));
        }
        return world_rows(u, w.body_pose(r.body), false);
      },
      py::arg("body"),
      "(N,3) each node's displacement from rest, world frame, metres (a copy): "
      "fem_node_positions − fem_rest_nodes.");
  def_world(
      cls, "fem_tets",
      [](const py::object& self, const py::object& body) {
        const FemRef r = fem_ref(world_of(self), body);
        const std::vector<TetIndices>& tets = r.solver().rest_mesh().tets;
        py::array_t<std::uint32_t> a({static_cast<py::ssize_t>(tets.size()), py::ssize_t{4}});
        std::uint32_t* o = a.mutable_data();
        for (std::size_t t = 0; t < tets.size(); ++t) {
          for (std::size_t k = 0; k < 4; ++k) {
            o[4 * t + k] = tets[t][k];
          }
        }
        return a;
      },
      py::arg("body"), "(T,4) uint32: each tetrahedron's nodes, positively oriented (a copy).");
  def_world(
      cls, "fem_regions",
      [](const py::object& self, const py::object& body) {
        const TetMesh& mesh = fem_ref(world_of(self), body).solver().rest_mesh();
        py::array_t<std::int32_t> a(static_cast<py::ssize_t>(mesh.tet_count()));
        std::int32_t* o = a.mutable_data();
        for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
          o[t] = mesh.region(t);
        }
        return a;
      },
      py::arg("body"), "(T,) int32: each tetrahedron's region (its material's; a copy).");
  def_world(
      cls, "fem_fixed_nodes",
      [](const py::object& self, const py::object& body) {
        const FemBody& s = fem_ref(world_of(self), body).solver();
        py::array_t<bool> a(static_cast<py::ssize_t>(s.node_count()));
        bool* o = a.mutable_data();
        for (std::size_t i = 0; i < s.node_count(); ++i) {
          o[i] = s.is_fixed(static_cast<std::uint32_t>(i));
        }
        return a;
      },
      py::arg("body"), "(N,) bool: whether each node is held fixed (a copy).");
  def_world(
      cls, "fem_von_mises_pa",
      [](const py::object& self, const py::object& body) {
        const FemBody& s = fem_ref(world_of(self), body).solver();
        std::vector<double> vm;
        s.von_mises_pa(vm);
        py::array_t<double> a(static_cast<py::ssize_t>(vm.size()));
        std::copy(vm.begin(), vm.end(), a.mutable_data());
        return a;
      },
      py::arg("body"), "(T,) each tetrahedron's von Mises stress now, Pa (a copy).");
  def_world(
      cls, "fem_stress_pa",
      [](const py::object& self, const py::object& body) {
        const World& w = world_of(self);
        const FemRef r = fem_ref(w, body);
        std::vector<Mat3> sigma;
        r.solver().element_stress_pa(sigma);
        const Mat3 R = w.body_pose(r.body).linear();
        py::array_t<double> a(
            {static_cast<py::ssize_t>(sigma.size()), py::ssize_t{3}, py::ssize_t{3}});
        double* o = a.mutable_data();
        for (std::size_t t = 0; t < sigma.size(); ++t) {
          const Mat3 s = R * sigma[t] * R.transpose();
          for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j) {
              o[9 * t + static_cast<std::size_t>(3 * i + j)] = s(i, j);
            }
          }
        }
        return a;
      },
      py::arg("body"),
      "(T,3,3) each tetrahedron's Cauchy stress now (symmetric), world frame, Pa (a copy).");
  def_world(
      cls, "fem_energies",
      [](const py::object& self, const py::object& body) {
        const FemBody& s = fem_ref(world_of(self), body).solver();
        py::dict out;
        out["elastic_j"] = s.elastic_energy_j();
        out["kinetic_j"] = s.kinetic_energy_j();
        return out;
      },
      py::arg("body"), "The body's elastic and kinetic energy now, J: elastic_j, kinetic_j.");
  def_world(
      cls, "fem_stats", [](const py::object& self) { return fem_stats(world_of(self)); },
      "The FEM coupling's figures so far (the 'fem' object of `hapsim run --json`: updates, "
      "period_steps, adopted, late_adopted, skipped_launches, update_ms, failures, bodies), or "
      "None for a world without FEM bodies.");
}

}  // namespace

void bind_fem(py::module_& m) {
  py::class_<PyTetMesh>(m, "TetMesh",
                        "A tetrahedral mesh (read_tet_mesh, make_tet_block, or arrays): nodes "
                        "(N,3) metres, tets (T,4), regions (T,)")
      .def(
          py::init([](const DoubleArray& nodes, const py::object& tets, const py::object& regions) {
            return tet_mesh_from_arrays(nodes, tets, regions);
          }),
          py::arg("nodes"), py::arg("tets"), py::arg("regions") = py::none(),
          "From arrays (copied; not validated: see quality() and validate()).")
      .def_property_readonly("source", [](const PyTetMesh& t) { return t.source; })
      .def_property_readonly("node_count", [](const PyTetMesh& t) { return t.mesh.node_count(); })
      .def_property_readonly("tet_count", [](const PyTetMesh& t) { return t.mesh.tet_count(); })
      .def_property_readonly(
          "nodes",
          [](const py::object& self) {
            return nodes_view(self, self.cast<const PyTetMesh&>().mesh.nodes);
          },
          "(N,3) node positions, metres (read-only view)")
      .def_property_readonly(
          "tets",
          [](const py::object& self) {
            return rows_view(self, self.cast<const PyTetMesh&>().mesh.tets);
          },
          "(T,4) uint32 node indices per tetrahedron (read-only view)")
      .def_property_readonly(
          "regions",
          [](const py::object& self) {
            const std::vector<std::int32_t>& r = self.cast<const PyTetMesh&>().regions;
            return view<std::int32_t>(self, r.data(), r.size(), 0, sizeof(std::int32_t));
          },
          "(T,) int32 region per tetrahedron (0 where the file has none; read-only view)")
      .def_property_readonly("volume_m3", [](const PyTetMesh& t) { return t.mesh.volume(); })
      .def(
          "quality", [](const PyTetMesh& t) { return quality_dict(tet_mesh_quality(t.mesh)); },
          "Shape quality as tet_mesh_quality() gives it.")
      .def(
          "validate",
          [](const PyTetMesh& t, bool allow_disconnected) {
            validate_tet_mesh(t.mesh, t.source, allow_disconnected);
          },
          py::arg("allow_disconnected") = false,
          "Raises hapsim.Error naming the first unusable element (index out of range, non-finite "
          "node, inverted or degenerate), an empty mesh or one in several pieces.")
      .def(
          "boundary",
          [](const PyTetMesh& t) {
            const TetBoundary b = tet_boundary(t.mesh);
            const auto nv = static_cast<py::ssize_t>(b.surface.vertices.size());
            const auto nt = static_cast<py::ssize_t>(b.surface.triangles.size());
            py::array_t<double> vertices({nv, py::ssize_t{3}});
            py::array_t<std::uint32_t> triangles({nt, py::ssize_t{3}});
            py::array_t<std::uint32_t> node(nv);
            for (py::ssize_t v = 0; v < nv; ++v) {
              const auto i = static_cast<std::size_t>(v);
              for (py::ssize_t k = 0; k < 3; ++k) {
                vertices.mutable_at(v, k) = b.surface.vertices[i][k];
              }
              node.mutable_at(v) = b.node_of_vertex[i];
            }
            for (py::ssize_t f = 0; f < nt; ++f) {
              for (py::ssize_t k = 0; k < 3; ++k) {
                triangles.mutable_at(f, k) =
                    b.surface.triangles[static_cast<std::size_t>(f)][static_cast<std::size_t>(k)];
              }
            }
            return py::make_tuple(vertices, triangles, node);
          },
          "The boundary surface (faces of exactly one tet, wound outward): (vertices (V,3), "
          "triangles (F,3), node_of_vertex (V,)) copies.");

  m.def(
      "read_tet_mesh",
      [](const std::filesystem::path& path, double scale) {
        if (!(scale > 0.0) || !std::isfinite(scale)) {
          throw Error("scale", "expected metres per file unit > 0");
        }
        TetMesh mesh;
        {
          py::gil_scoped_release release;
          mesh = read_tet_mesh(path);
        }
        mesh.scale(scale);
        return make_py_tet_mesh(std::move(mesh), path.string());
      },
      py::arg("path"), py::arg("scale") = 1.0,
      "Reads a tet mesh (.msh Gmsh 4.1 ASCII, TetGen .node/.ele, legacy VTK ASCII), validated as "
      "`hapsim info` does; a bad file raises hapsim.Error naming the file, line and element.");
  m.def(
      "make_tet_block",
      [](const DoubleArray& size_m, const DoubleArray& cells, const DoubleArray& origin_m) {
        const Vec3 size = to_vec3(size_m, "size_m");
        if (!(size.minCoeff() > 0.0) || !(size.maxCoeff() <= 100.0)) {
          throw Error("size_m", "expected three sizes in (0, 100] m");
        }
        if (cells.ndim() != 1 || cells.shape(0) != 3) {
          throw Error("cells", "expected three cell counts [nx, ny, nz]");
        }
        std::array<int, 3> n{};
        double total = 6.0;
        for (py::ssize_t i = 0; i < 3; ++i) {
          const double v = cells.at(i);
          if (!(v >= 1.0 && v <= 200.0) || v != std::floor(v)) {
            throw Error("cells", "expected a whole number of cells in 1..200");
          }
          n[static_cast<std::size_t>(i)] = static_cast<int>(v);
          total *= v;
        }
        if (total > 2e6) {
          throw Error("cells", "more than 2 million tetrahedra");
        }
        TetMesh mesh = make_tet_block(size, n);
        mesh.transform(Iso3(Eigen::Translation3d(to_vec3(origin_m, "origin_m"))));
        return make_py_tet_mesh(std::move(mesh), "tet block");
      },
      py::arg("size_m"), py::arg("cells"), py::arg("origin_m") = py::make_tuple(0.0, 0.0, 0.0),
      "A box [0, size_m] moved by origin_m, cells[i] cubes along each axis, 6 tets per cube (as "
      "a scene's tet_block).");
  m.def(
      "tet_mesh_quality", [](const PyTetMesh& t) { return quality_dict(tet_mesh_quality(t.mesh)); },
      py::arg("mesh"),
      "Shape quality: tets, nodes, min/max_dihedral_deg, max_aspect_ratio (1: regular), "
      "min_volume_m3, total_volume_m3, inverted, degenerate, components, unused_nodes, "
      "out_of_range, non_finite.");

  bind_world_fem(m);
}

}  // namespace hapsim::python
