// hapsim.Mesh, hapsim.load_mesh and hapsim.Chain (docs/python.md#meshes-and-chains): meshes
// loaded as the CLI loads them and queried for the closest point over an N×3 array (the GIL
// released, as `hapsim query` walks its points: each answer hints the next); serial chains from a
// URDF, forward and inverse kinematics.
#include "arrays.h"
#include "bindings.h"

#include "hapsim/collision/knee_index.h"
#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/collision/sphere_tree.h"
#include "hapsim/geometry/mesh_argument.h"
#include "hapsim/kinematics/inverse_kinematics.h"
#include "hapsim/kinematics/urdf_chain.h"

#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace hapsim::python {
namespace {

struct PyMesh {
  MeshArgument loaded;
  // Built on first use per method: exact, spheretree, knee.
  std::array<std::unique_ptr<ProximityQuery>, 3> queries;
};

const ProximityQuery& query_for(PyMesh& mesh, const std::string& method) {
  static const std::array<const char*, 3> kNames = {"exact", "spheretree", "knee"};
  for (std::size_t i = 0; i < kNames.size(); ++i) {
    if (method == kNames[i]) {
      if (!mesh.queries[i]) {
        py::gil_scoped_release release;
        const TriangleMesh& m = mesh.loaded.mesh;
        mesh.queries[i] = i == 0 ? std::unique_ptr<ProximityQuery>(std::make_unique<MeshBvh>(m))
                          : i == 1
                              ? std::unique_ptr<ProximityQuery>(std::make_unique<SphereTree>(m))
                              : std::unique_ptr<ProximityQuery>(std::make_unique<KneeIndex>(m));
      }
      return *mesh.queries[i];
    }
  }
  throw Error("method", "expected 'exact', 'spheretree' or 'knee', got '" + method + "'");
}

py::dict closest(PyMesh& mesh, const DoubleArray& points, const std::string& method) {
  if (points.ndim() != 2 || points.shape(1) != 3) {
    throw Error("points", "expected an N×3 array of metres");
  }
  const ProximityQuery& query = query_for(mesh, method);
  const py::ssize_t n = points.shape(0);
  py::array_t<double> distance(n);
  py::array_t<double> point({n, py::ssize_t{3}});
  py::array_t<double> normal({n, py::ssize_t{3}});
  py::array_t<std::int64_t> triangle(n);
  const double* in = points.data();
  for (py::ssize_t i = 0; i < 3 * n; ++i) {
    if (!std::isfinite(in[i])) {
      throw Error("points", "row " + std::to_string(i / 3) +
                                " is not finite (NaN or infinity): a closest point needs a point");
    }
  }
  double* d = distance.mutable_data();
  double* p = point.mutable_data();
  double* nn = normal.mutable_data();
  std::int64_t* t = triangle.mutable_data();
  {
    py::gil_scoped_release release;
    QueryHint hint;  // consecutive points are usually close: the last answer bounds the next
    for (py::ssize_t i = 0; i < n; ++i) {
      const SurfacePoint s =
          query.closest_point(Vec3(in[3 * i], in[3 * i + 1], in[3 * i + 2]), &hint);
      d[i] = s.signed_distance;
      for (int j = 0; j < 3; ++j) {
        p[3 * i + j] = s.point[j];
        nn[3 * i + j] = s.normal[j];
      }
      t[i] = s.found() && s.triangle != kSdfSurface ? static_cast<std::int64_t>(s.triangle) : -1;
    }
  }
  py::dict out;
  out["signed_distance"] = distance;
  out["point"] = point;
  out["normal"] = normal;
  out["triangle"] = triangle;
  return out;
}

std::vector<double> joint_values(const SerialChain& chain, const double* q) {
  return {q, q + chain.dof()};
}

}  // namespace

Iso3 to_iso3(const DoubleArray& a, const char* what) {
  if (a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4) {
    throw Error(what, "expected a 4×4 homogeneous transform");
  }
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      R(r, c) = a.at(r, c);
    }
  }
  Iso3 X = Iso3::Identity();
  X.linear() = Quat(R).normalized().toRotationMatrix();
  X.translation() = Vec3(a.at(0, 3), a.at(1, 3), a.at(2, 3));
  return X;
}

void bind_geometry(py::module_& m) {
  py::class_<PyMesh>(m, "Mesh", "A triangle mesh in metres (load_mesh)")
      .def_property_readonly("name", [](const PyMesh& s) { return s.loaded.name; })
      .def_property_readonly("validation", [](const PyMesh& s) { return s.loaded.validation; })
      .def_property_readonly("vertices",
                             [](const py::object& self) {
                               const TriangleMesh& mesh = self.cast<const PyMesh&>().loaded.mesh;
                               return view<double>(
                                   self, mesh.vertices.empty() ? nullptr : mesh.vertices[0].data(),
                                   mesh.vertices.size(), 3, sizeof(Vec3));
                             })
      .def_property_readonly("triangles",
                             [](const py::object& self) {
                               const TriangleMesh& mesh = self.cast<const PyMesh&>().loaded.mesh;
                               return view<std::uint32_t>(
                                   self,
                                   mesh.triangles.empty() ? nullptr : mesh.triangles[0].data(),
                                   mesh.triangles.size(), 3, sizeof(TriangleIndices));
                             })
      .def("closest", &closest, py::arg("points"), py::arg("method") = "exact",
           "Closest surface point to each row of an N×3 array: signed_distance (N,), point "
           "(N,3), normal (N,3), triangle (N,; -1 none); the GIL released while it runs.");
  m.def(
      "load_mesh",
      [](const std::string& spec, double scale) {
        auto mesh = std::make_unique<PyMesh>();
        py::gil_scoped_release release;
        mesh->loaded = load_mesh_argument(spec, scale);
        if (mesh->loaded.mesh.empty()) {
          throw Error(spec, "the mesh has no triangles");
        }
        return mesh;
      },
      py::arg("path"), py::arg("scale") = 1.0,
      "Loads a mesh file (scaled to metres) or builtin:NAME, validated as the CLI does.");

  py::class_<SerialChain>(m, "Chain", "A serial chain from a URDF (load_chain)")
      .def_property_readonly("dof", &SerialChain::dof)
      .def_property_readonly("base_link", &SerialChain::base_link)
      .def_property_readonly("tip_link", &SerialChain::tip_link)
      .def_property_readonly("joint_names",
                             [](const SerialChain& c) {
                               py::list out;
                               for (const ChainJoint& j : c.joints()) {
                                 out.append(j.name);
                               }
                               return out;
                             })
      .def_property_readonly(
          "limits",
          [](const SerialChain& c) {
            py::array_t<double> a({static_cast<py::ssize_t>(c.dof()), py::ssize_t{2}});
            auto o = a.mutable_unchecked<2>();
            for (int i = 0; i < c.dof(); ++i) {
              o(i, 0) = c.joints()[static_cast<std::size_t>(i)].lower;
              o(i, 1) = c.joints()[static_cast<std::size_t>(i)].upper;
            }
            return a;
          })
      .def(
          "forward",
          [](const SerialChain& c, const DoubleArray& q) -> py::array_t<double> {
            const auto dof = static_cast<py::ssize_t>(c.dof());
            if (q.ndim() == 1 && q.shape(0) == dof) {
              return from_iso3(c.forward(joint_values(c, q.data())));
            }
            if (q.ndim() != 2 || q.shape(1) != dof) {
              throw Error("q", "expected " + std::to_string(dof) + " joint values or an M×" +
                                   std::to_string(dof) + " array");
            }
            const py::ssize_t rows = q.shape(0);
            py::array_t<double> out({rows, py::ssize_t{4}, py::ssize_t{4}});
            double* o = out.mutable_data();
            const double* in = q.data();
            py::gil_scoped_release release;
            for (py::ssize_t r = 0; r < rows; ++r) {
              const Eigen::Matrix4d M =
                  c.forward(std::span<const double>(in + r * dof, static_cast<std::size_t>(dof)))
                      .matrix();
              Eigen::Map<Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(o + 16 * r) = M;
            }
            return out;
          },
          py::arg("q"),
          "The tip's pose (4×4, base frame) for joint values q, or (M,4,4) for M rows")
      .def(
          "inverse",
          [](const SerialChain& c, const DoubleArray& target, std::optional<DoubleArray> seed,
             bool orientation) {
            const Iso3 X = to_iso3(target, "target");
            std::vector<double> q0(static_cast<std::size_t>(c.dof()), 0.0);
            if (seed) {
              if (seed->ndim() != 1 || seed->shape(0) != c.dof()) {
                throw Error("seed", "expected " + std::to_string(c.dof()) + " joint values");
              }
              q0 = joint_values(c, seed->data());
            } else {
              for (std::size_t i = 0; i < q0.size(); ++i) {
                const ChainJoint& j = c.joints()[i];
                q0[i] = std::isfinite(j.lower) && std::isfinite(j.upper) ? 0.5 * (j.lower + j.upper)
                                                                         : 0.0;
              }
            }
            py::array_t<double> q(c.dof());
            IkOptions options;
            options.orientation = orientation;
            const IkResult r = solve_ik(
                c, X, q0, std::span<double>(q.mutable_data(), static_cast<std::size_t>(c.dof())),
                options);
            py::dict out;
            out["q"] = q;
            out["reached"] = r.reached;
            out["position_error_m"] = r.position_error_m;
            out["rotation_error_rad"] = r.rotation_error_rad;
            return out;
          },
          py::arg("target"), py::arg("seed") = py::none(), py::arg("orientation") = true,
          "Joint values putting the tip at target (4×4), from seed (default: mid-limits)");
  m.def(
      "load_chain",
      [](const std::string& urdf, const std::string& base, const std::string& tip) {
        UrdfChainOptions o;
        o.base_link = base;
        o.tip_link = tip;
        o.load_collision_meshes = false;  // not needed for kinematics
        return load_urdf_chain(urdf, o);
      },
      py::arg("urdf"), py::arg("base") = "", py::arg("tip") = "",
      "A serial chain from a URDF, base to tip (default: the root and the deepest leaf).");
}

}  // namespace hapsim::python
