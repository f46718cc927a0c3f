// hapsim.World and hapsim.DeviceInput (docs/python.md#the-world): one scene's world, stepped from
// Python with a device input, read as NumPy arrays. Python never runs inside the real-time loop:
// a World stepped from here is a script's or a test's, on the calling thread.
#include "arrays.h"
#include "bindings.h"

#include "hapsim/deform/vertex_deflection.h"
#include "hapsim/device/force_safety.h"
#include "hapsim/device/input_check.h"
#include "hapsim/device/recording.h"
#include "hapsim/runtime/cycle_record.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"

#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>

namespace hapsim::python {
namespace {

// A world built as `hapsim run` builds it (materials no stiffer than the device's rating), with
// the scene's own scripted device beside it for script_input().
struct PyWorld {
  RunSetup setup;
  double dt_s = 0.001;
  std::unique_ptr<SessionRecorder> recorder;
  std::uint64_t recorded_cycles = 0;
  std::unique_ptr<CycleRecord> record = std::make_unique<CycleRecord>();
  /// The last step's command as the device renders it and a recording holds it: clamped to the
  /// device's profile (what run_session does), so Python reads what a trainee would feel.
  DeviceCommand command;
  std::uint64_t clamped_steps = 0;

  World& world() { return *setup.world; }
  [[nodiscard]] const World& world() const { return *setup.world; }
};

// "12.0 N" or "4.0 N per finger" (and the tip's, when a glove has one), for the clamp's warning.
std::string describe_rating(const DeviceProfile& profile) {
  std::string out;
  char text[64];
  if (profile.max_force_n > 0.0) {
    std::snprintf(text, sizeof text, "%.1f N", profile.max_force_n);
    out = text;
  }
  if (profile.finger_count > 0) {
    std::snprintf(text, sizeof text, "%s%.1f N per finger", out.empty() ? "" : ", ",
                  profile.max_finger_force_n);
    out += text;
  }
  return out.empty() ? std::string("rated 0 N") : out;
}

template <class Fixed>
void set_channels(const DoubleArray& values, Fixed& out, int& count, const char* what) {
  if (values.ndim() != 1 || values.shape(0) > static_cast<py::ssize_t>(out.size())) {
    throw Error(what, "expected at most " + std::to_string(out.size()) + " values");
  }
  out.fill(0.0);
  count = static_cast<int>(values.shape(0));
  for (int i = 0; i < count; ++i) {
    out[static_cast<std::size_t>(i)] = values.at(i);
  }
}

template <class Fixed>
py::array_t<double> channels(const Fixed& values, int count) {
  py::array_t<double> a(count);
  auto o = a.mutable_unchecked<1>();
  for (int i = 0; i < count; ++i) {
    o(i) = values[static_cast<std::size_t>(i)];
  }
  return a;
}

Quat to_quat(const DoubleArray& a) {
  if (a.ndim() != 1 || a.shape(0) != 4) {
    throw Error("q_world", "expected 4 numbers w, x, y, z");
  }
  const Quat q(a.at(0), a.at(1), a.at(2), a.at(3));
  if (!(std::abs(q.norm() - 1.0) < 1e-6)) {
    throw Error("q_world", "expected a unit quaternion, its norm is " + std::to_string(q.norm()));
  }
  return q;
}

std::uint32_t material_index(const World& w, const std::string& name) {
  const auto& materials = w.description().materials;
  for (std::size_t i = 0; i < materials.size(); ++i) {
    if (materials[i].name == name) {
      return static_cast<std::uint32_t>(i);
    }
  }
  std::string known;
  for (const MaterialDescription& m : materials) {
    known += (known.empty() ? "" : ", ") + m.name;
  }
  throw Error("material", "no material '" + name + "'; the world has " + known);
}

void check_segment(const World& w, std::size_t body, std::size_t segment) {
  if (body >= w.body_count() || segment >= w.segment_count(body)) {
    throw py::index_error("no segment " + std::to_string(segment) + " of body " +
                          std::to_string(body));
  }
}

std::unique_ptr<PyWorld> make_world(const py::object& scene,
                                    const std::optional<std::string>& method,
                                    const std::optional<std::string>& data_dir) {
  RunSetupOptions options;
  if (method) {
    options.method = parse_contact_method(*method);
    if (!options.method) {
      throw Error("method", "expected 'exact', 'spheretree' or 'knee', got '" + *method + "'");
    }
  }
  auto w = std::make_unique<PyWorld>();
  // A Scene object's description is copied (its meshes are not read again); a path is loaded.
  std::optional<SceneDescription> loaded;
  if (py::isinstance<Scene>(scene)) {
    loaded = *scene.cast<const Scene&>().description;
  }
  const std::string path = loaded ? std::string() : std::string(py::str(scene));
  SceneLoadOptions load_options;
  if (data_dir) {
    load_options.data_dir = *data_dir;
  }
  try {
    py::gil_scoped_release release;
    if (!loaded) {
      loaded = load_scene(path, load_options);
    }
    w->setup = make_run_setup(std::move(*loaded), DeviceChoice::scene_script(), options);
  } catch (const Error& e) {
    raise_scene_error(e);
  }
  w->dt_s = w->setup.scene.run.dt_s;
  return w;
}

// Not the haptic path: Python's own step, on the calling thread (what a script or a test does).
void step(PyWorld& w, const DeviceInput& input, std::optional<double> dt_s) {
  const double dt = dt_s.value_or(w.dt_s);
  if (!(dt > 0.0) || !std::isfinite(dt)) {
    throw Error("dt", "expected seconds > 0");
  }
  // Refused where it enters: a NaN or inf input would poison the world and the recording (whose
  // readers refuse a file holding one). hapsim.Error is a ValueError.
  if (const std::string bad = nonfinite_input_field(input); !bad.empty()) {
    throw Error("World.step(input)", "input." + bad +
                                         ": device input must be finite (nothing was stepped "
                                         "or recorded)");
  }
  const StepResult& result = w.world().step(input, dt);
  // What run_session renders and records: the world's command clamped to the device.
  ClampReport clamp;
  w.command = clamp_command(result.command, *w.setup.profile, &clamp);
  if (clamp.changed() && w.clamped_steps++ == 0) {
    // Said once (the count is World.clamped_steps): the device's limit, not the world's force.
    const std::string said = "World.step: the command exceeded the device '" +
                             w.setup.profile->name + "' (" + describe_rating(*w.setup.profile) +
                             "); force_world_n, finger_force_n and joint_torque_nm are clamped "
                             "to it, as the device renders and a recording holds them";
    if (PyErr_WarnEx(PyExc_RuntimeWarning, said.c_str(), 1) != 0) {
      throw py::error_already_set();
    }
  }
  if (w.recorder) {
    fill_cycle_record(*w.record, w.recorded_cycles, input, result, w.command, 0.0);
    if (!w.recorder->record(to_recorded_frame(*w.record, *w.setup.profile))) {
      throw Error(w.recorder->path().string(), "recording failed: " + w.recorder->last_error());
    }
    ++w.recorded_cycles;
    if (w.recorder->flush_due()) {
      w.recorder->flush();  // every 100 ms of the session: a killed interpreter keeps the rest
    }
  }
}

py::dict contacts(const World& w) {
  const auto& c = w.last_result().contacts;
  const auto n = static_cast<py::ssize_t>(c.size());
  py::array_t<std::int32_t> tool(n);
  py::array_t<std::int32_t> body(n);
  py::array_t<std::int32_t> segment(n);
  py::array_t<double> point({n, py::ssize_t{3}});
  py::array_t<double> normal({n, py::ssize_t{3}});
  py::array_t<double> depth(n);
  py::array_t<double> force(n);
  py::array_t<bool> proxy(n);
  auto t = tool.mutable_unchecked<1>();
  auto b = body.mutable_unchecked<1>();
  auto s = segment.mutable_unchecked<1>();
  auto p = point.mutable_unchecked<2>();
  auto nn = normal.mutable_unchecked<2>();
  auto d = depth.mutable_unchecked<1>();
  auto f = force.mutable_unchecked<1>();
  auto x = proxy.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < n; ++i) {
    const WorldContact& k = c[static_cast<std::size_t>(i)];
    t(i) = k.tool.value;
    b(i) = k.body.value;
    s(i) = k.segment.value;  // body-local, as Python's World.contacts() documents
    for (py::ssize_t j = 0; j < 3; ++j) {
      p(i, j) = k.point_world[j];
      nn(i, j) = k.normal_world[j];
    }
    d(i) = k.depth_m;
    f(i) = k.force_n;
    x(i) = k.proxy;
  }
  py::dict out;
  out["tool"] = tool;
  out["body"] = body;
  out["segment"] = segment;
  out["point_world"] = point;
  out["normal_world"] = normal;
  out["depth_m"] = depth;
  out["force_n"] = force;
  out["proxy"] = proxy;
  return out;
}

// The tools' states as (tools, 3) views of the world's own storage (sized when it was built).
template <class Field>
py::array_t<double> tool_view(const py::object& self, Field field) {
  const World& w = self.cast<const PyWorld&>().world();
  const auto tools = w.state().result.tools;
  static const ToolState kNone{};
  return view<double>(self, field(tools.empty() ? kNone : tools.front()), tools.size(), 3,
                      sizeof(ToolState));
}

}  // namespace

const World& world_of(const py::handle& py_world) {
  return py_world.cast<const PyWorld&>().world();
}

void bind_world(py::module_& m) {
  py::class_<DeviceInput>(m, "DeviceInput",
                          "One cycle of device input: pose, finger angles, joints (SI units)")
      .def(py::init([](const DoubleArray& p_world, const DoubleArray& q_world,
                       const DoubleArray& finger_rad, const DoubleArray& joint_rad, double time_s,
                       std::uint32_t buttons, bool healthy) {
             DeviceInput in;
             in.p_world = to_vec3(p_world, "p_world");
             in.q_world = to_quat(q_world);
             set_channels(finger_rad, in.finger_rad, in.finger_count, "finger_rad");
             set_channels(joint_rad, in.joint_rad, in.joint_count, "joint_rad");
             in.time_s = time_s;
             in.buttons = buttons;
             in.healthy = healthy;
             return in;
           }),
           py::arg("p_world") = py::make_tuple(0.0, 0.0, 0.0),
           py::arg("q_world") = py::make_tuple(1.0, 0.0, 0.0, 0.0),
           py::arg("finger_rad") = py::tuple(), py::arg("joint_rad") = py::tuple(),
           py::arg("time_s") = 0.0, py::arg("buttons") = 0, py::arg("healthy") = true)
      .def_readwrite("time_s", &DeviceInput::time_s)
      .def_readwrite("buttons", &DeviceInput::buttons)
      .def_readwrite("healthy", &DeviceInput::healthy)
      .def_property(
          "p_world", [](const DeviceInput& in) { return from_vec3(in.p_world); },
          [](DeviceInput& in, const DoubleArray& p) { in.p_world = to_vec3(p, "p_world"); })
      .def_property(
          "q_world",
          [](const DeviceInput& in) {
            py::array_t<double> a(4);
            auto o = a.mutable_unchecked<1>();
            o(0) = in.q_world.w();
            o(1) = in.q_world.x();
            o(2) = in.q_world.y();
            o(3) = in.q_world.z();
            return a;
          },
          [](DeviceInput& in, const DoubleArray& q) { in.q_world = to_quat(q); })
      .def_property(
          "finger_rad",
          [](const DeviceInput& in) { return channels(in.finger_rad, in.finger_count); },
          [](DeviceInput& in, const DoubleArray& v) {
            set_channels(v, in.finger_rad, in.finger_count, "finger_rad");
          })
      .def_property(
          "joint_rad", [](const DeviceInput& in) { return channels(in.joint_rad, in.joint_count); },
          [](DeviceInput& in, const DoubleArray& v) {
            set_channels(v, in.joint_rad, in.joint_count, "joint_rad");
          });

  py::class_<PyWorld>(m, "World", "A scene's world, stepped from Python (docs/python.md)")
      .def(py::init(&make_world), py::arg("scene"), py::arg("method") = py::none(),
           py::arg("data_dir") = py::none())
      .def("step", &step, py::arg("input"), py::arg("dt") = py::none(),
           "Advances by dt (default: the scene's run.dt_s) with this input.")
      .def(
          "script_input", [](PyWorld& w, double time_s) { return w.setup.device->read(time_s); },
          py::arg("time_s"),
          "The scene's own scripted device's input at time_s (call once per step, in order).")
      .def("reset",
           [](PyWorld& w) {
             w.world().reset();
             w.command = DeviceCommand{};
           })
      .def_property_readonly("dt_s", [](const PyWorld& w) { return w.dt_s; })
      .def_property_readonly("duration_s", [](const PyWorld& w) { return w.setup.duration_s; })
      .def_property_readonly("time_s",
                             [](const PyWorld& w) { return w.world().last_result().time_s; })
      .def_property_readonly("device_name", [](const PyWorld& w) { return w.setup.device_name; })
      .def_property_readonly("content_hash",
                             [](const PyWorld& w) { return w.world().content_hash(); })
      .def_property_readonly("tool_names",
                             [](const PyWorld& w) {
                               py::list out;
                               for (const ToolDescription& t : w.world().description().tools) {
                                 out.append(t.name);
                               }
                               return out;
                             })
      .def_property_readonly("body_names",
                             [](const PyWorld& w) {
                               py::list out;
                               for (const BodyDescription& b : w.world().description().bodies) {
                                 out.append(b.name);
                               }
                               return out;
                             })
      .def(
          "segment_names",
          [](const PyWorld& w, std::size_t body) {
            if (body >= w.world().body_count()) {
              throw py::index_error("no body " + std::to_string(body));
            }
            py::list out;
            for (const SegmentDescription& s : w.world().description().bodies[body].segments) {
              out.append(s.name);
            }
            return out;
          },
          py::arg("body"))
      .def(
          "segment_material",
          [](const PyWorld& w, std::size_t body, std::size_t segment) {
            check_segment(w.world(), body, segment);
            const WorldDescription& d = w.world().description();
            return d.materials[d.bodies[body].segments[segment].material].name;
          },
          py::arg("body"), py::arg("segment"))
      .def_property_readonly(
          "material_names",
          [](const PyWorld& w) {
            py::list out;
            for (const MaterialDescription& mat : w.world().description().materials) {
              out.append(mat.name);
            }
            return out;
          })
      .def(
          "stiffness_n_per_m",
          [](const PyWorld& w, const std::string& material) {
            return w.world()
                .material_contact(material_index(w.world(), material))
                .stiffness_n_per_m;
          },
          py::arg("material"), "A material's stiffness as edited live (before the device's clamp)")
      .def(
          "effective_stiffness_n_per_m",
          [](const PyWorld& w, const std::string& material) {
            return w.world()
                .effective_material(material_index(w.world(), material), w.dt_s)
                .stiffness_n_per_m;
          },
          py::arg("material"), "The stiffness a step uses: no stiffer than the device's rating")
      .def(
          "set_stiffness",
          [](PyWorld& w, const std::string& material, double stiffness_n_per_m) {
            const std::uint32_t i = material_index(w.world(), material);
            ContactMaterial c = w.world().material_contact(i);
            c.stiffness_n_per_m = stiffness_n_per_m;
            if (!w.world().set_material_contact(i, c)) {
              throw Error("stiffness_n_per_m", "the world refused " +
                                                   std::to_string(stiffness_n_per_m) + " N/m for " +
                                                   material);
            }
          },
          py::arg("material"), py::arg("stiffness_n_per_m"),
          "From the next step on (the device's rated stiffness still applies)")
      .def_property_readonly("tool_p_world",
                             [](const py::object& self) {
                               return tool_view(
                                   self, [](const ToolState& t) { return t.p_world.data(); });
                             })
      .def_property_readonly("tool_proxy_world",
                             [](const py::object& self) {
                               return tool_view(
                                   self, [](const ToolState& t) { return t.proxy_world.data(); });
                             })
      .def_property_readonly("tool_force_world_n",
                             [](const py::object& self) {
                               return tool_view(
                                   self, [](const ToolState& t) { return t.force_world_n.data(); });
                             })
      .def_property_readonly(
          "force_world_n", [](const PyWorld& w) { return from_vec3(w.command.force_world_n); },
          "The tip force the device renders (clamped to its rating, as recorded), N")
      .def_property_readonly(
          "finger_force_n",
          [](const PyWorld& w) {
            return channels(w.command.finger_force_n, w.command.finger_count);
          },
          "The finger forces the device renders (clamped to its rating, as recorded), N")
      .def_property_readonly(
          "joint_torque_nm",
          [](const PyWorld& w) {
            return channels(w.command.joint_torque_nm, w.command.joint_count);
          },
          "The joint torques the device renders (clamped to its rating, as recorded), N m")
      .def_property_readonly(
          "clamped_steps", [](const PyWorld& w) { return w.clamped_steps; },
          "Steps whose command the device's limits clamped (warned once, at the first)")
      .def("contacts", [](const PyWorld& w) { return contacts(w.world()); })
      .def(
          "body_pose",
          [](const PyWorld& w, std::size_t body) {
            if (body >= w.world().body_count()) {
              throw py::index_error("no body " + std::to_string(body));
            }
            return from_iso3(w.world().body_pose(body));
          },
          py::arg("body"))
      .def(
          "deflection_m",
          [](const PyWorld& w, std::size_t body, std::size_t segment) -> py::object {
            check_segment(w.world(), body, segment);
            const VertexDeflection* d = w.world().deflection(body, segment);
            if (d == nullptr) {
              return py::none();
            }
            const auto n = d->rest_positions().size();
            py::array_t<double> a(static_cast<py::ssize_t>(n));
            auto o = a.mutable_unchecked<1>();
            for (std::size_t v = 0; v < n; ++v) {
              o(static_cast<py::ssize_t>(v)) = d->deflection_m(static_cast<std::uint32_t>(v));
            }
            return a;
          },
          py::arg("body"), py::arg("segment"),
          "Each vertex's deflection now, metres (None: not deformable)")
      .def(
          "surface",
          [](const py::object& self, std::size_t body, std::size_t segment) {
            const World& w = self.cast<const PyWorld&>().world();
            check_segment(w, body, segment);
            const TriangleMesh& mesh = w.surface(body, segment);
            return py::make_tuple(
                view<double>(self, mesh.vertices.empty() ? nullptr : mesh.vertices.front().data(),
                             mesh.vertices.size(), 3, sizeof(Vec3)),
                view<std::uint32_t>(
                    self, mesh.triangles.empty() ? nullptr : mesh.triangles.front().data(),
                    mesh.triangles.size(), 3, sizeof(mesh.triangles.front())));
          },
          py::arg("body"), py::arg("segment"),
          "The segment's surface now (body frame): (vertices (V,3), triangles (T,3)) views")
      .def(
          "record",
          [](PyWorld& w, const std::string& path) {
            w.recorder = std::make_unique<SessionRecorder>(path, w.world().content_hash(), 8192,
                                                           SessionRecorder::Overflow::kFlushInline);
            w.recorded_cycles = 0;
          },
          py::arg("path"), "Records every following step (input, clamped command, contacts)")
      .def(
          "stop_recording",
          [](PyWorld& w) {
            if (!w.recorder) {
              return std::size_t{0};
            }
            w.recorder->close();
            const std::size_t frames = w.recorder->frames_written();
            w.recorder.reset();
            return frames;
          },
          "Closes the recording; returns the frames written");
}

}  // namespace hapsim::python
