// The `hapsim` Python module's entry (docs/python.md): errors, scenes, runs of a scene's own
// device (the same summary as `hapsim run --json`), replays and recordings. The world and the
// geometry are bound in their own files (bindings.h).
#include "arrays.h"
#include "bindings.h"

#include "hapsim/device/recording.h"
#include "hapsim/runtime/session.h"
#include "hapsim/runtime/session_json.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

namespace hapsim::python {
namespace {

PyObject* g_error = nullptr;
PyObject* g_scene_error = nullptr;

// "scene.json:/bodies/2/material" -> file "scene.json", pointer "/bodies/2/material"; a JSON
// syntax error "scene.json:3:14" -> file and "3:14"; otherwise the whole of `where` is the file.
std::pair<std::string, std::string> split_where(const std::string& where) {
  if (const std::size_t p = where.find(":/"); p != std::string::npos) {
    return {where.substr(0, p), where.substr(p + 1)};
  }
  const std::size_t last = where.rfind(':');
  if (last != std::string::npos && last > 0) {
    const std::size_t before = where.rfind(':', last - 1);
    if (before != std::string::npos &&
        where.find_first_not_of("0123456789:", before) == std::string::npos) {
      return {where.substr(0, before), where.substr(before + 1)};
    }
  }
  return {where, ""};
}

// Sets the Python error `type` for `e`, with its parts as attributes.
void set_error(PyObject* type, const Error& e) {
  const auto [file, pointer] = split_where(e.where());
  py::object error = py::reinterpret_borrow<py::object>(type)(e.what());
  error.attr("where") = e.where();
  error.attr("detail") = e.detail();
  error.attr("file") = file;
  error.attr("pointer") = pointer.empty() ? py::object(py::none()) : py::object(py::str(pointer));
  PyErr_SetObject(type, error.ptr());
}

[[noreturn]] void raise(PyObject* type, const Error& e) {
  set_error(type, e);
  throw py::error_already_set();
}

SceneDescription load(const std::string& path, const std::optional<std::string>& data_dir) {
  SceneLoadOptions options;
  if (data_dir) {
    options.data_dir = *data_dir;
  }
  try {
    py::gil_scoped_release release;
    return load_scene(path, options);
  } catch (const Error& e) {
    raise_scene_error(e);
  }
}

py::object json_to_python(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

std::optional<ContactMethod> method_option(const std::optional<std::string>& name) {
  if (!name) {
    return std::nullopt;
  }
  const std::optional<ContactMethod> m = parse_contact_method(*name);
  if (!m) {
    throw Error("method", "expected 'exact', 'spheretree' or 'knee', got '" + *name + "'");
  }
  return m;
}

// `hapsim run SCENE [--duration S] [--method M] [--record F | --replay F] --json`, from Python.
py::object run(const py::object& scene_arg, std::optional<double> duration_s,
               const std::optional<std::string>& method, const std::optional<std::string>& record,
               const std::optional<std::string>& replay,
               const std::optional<std::string>& data_dir) {
  if (duration_s && !(*duration_s > 0.0 && std::isfinite(*duration_s))) {
    throw Error("duration", "expected seconds > 0");
  }
  if (record && replay) {
    throw Error("record", "not with replay= (a replay records to compare by itself)");
  }
  SceneDescription description = py::isinstance<Scene>(scene_arg)
                                     ? *scene_arg.cast<const Scene&>().description
                                     : load(py::str(scene_arg), data_dir);
  RunSetupOptions setup_options;
  setup_options.method = method_option(method);
  const DeviceChoice choice = replay ? DeviceChoice::replay(*replay) : DeviceChoice::scene_script();
  py::gil_scoped_release release;
  RunSetup setup = [&] {
    try {
      return make_run_setup(std::move(description), choice, setup_options);
    } catch (const Error& e) {
      py::gil_scoped_acquire acquire;
      raise_scene_error(e);
    }
  }();
  const double length_s = duration_s.value_or(setup.duration_s);
  if (!(length_s > 0.0) || !std::isfinite(length_s)) {
    throw Error(setup.scene.file.string(), "the run has no length (give duration=S)");
  }
  if (!(length_s / setup.scene.run.dt_s <= max_session_steps(false))) {
    throw Error(setup.scene.file.string(),
                "a run of " + std::to_string(length_s) + " s is more than " +
                    std::to_string(max_session_steps(false)) + " steps (give a shorter duration)");
  }
  // A replay records to a temporary file to compare with its recording, as the CLI does.
  std::filesystem::path record_path = record.value_or("");
  if (replay) {
    record_path = std::filesystem::temp_directory_path() /
                  ("hapsim_python_replay_" + std::to_string(::getpid()) + ".rec");
  }
  std::unique_ptr<SessionRecorder> recorder;
  if (!record_path.empty()) {
    recorder = std::make_unique<SessionRecorder>(record_path, setup.world->content_hash(), 8192,
                                                 SessionRecorder::Overflow::kFlushInline,
                                                 setup.scene.file);
  }
  SessionOptions options;
  options.duration_s = length_s;
  options.dt_s = setup.scene.run.dt_s;
  options.recorder = recorder.get();
  options.teleop_target_world = setup.teleop_target_world;
  const SessionSummary summary = run_session(*setup.world, *setup.device, options);
  std::optional<RecordingDifference> difference;
  if (recorder) {
    recorder->close();
  }
  if (replay) {
    difference = compare_recording_files(setup.replayed_file, record_path);
    std::error_code ec;
    std::filesystem::remove(record_path, ec);
  }
  const nlohmann::json j = run_summary_json(setup, summary, difference ? &*difference : nullptr);
  py::gil_scoped_acquire acquire;
  return json_to_python(j);
}

// A recording in memory; its arrays are views of its frames (the Recording object owns them).
struct PyRecording {
  Recording recording;
};

template <class Field>
py::array_t<double> frame_view(const py::object& self, std::size_t cols, Field field) {
  const auto& frames = self.cast<const PyRecording&>().recording.frames;
  static const RecordedFrame kEmpty{};
  const RecordedFrame& first = frames.empty() ? kEmpty : frames.front();
  return view<double>(self, field(first), frames.size(), cols, sizeof(RecordedFrame));
}

}  // namespace

[[noreturn]] void raise_scene_error(const Error& e) {
  raise(g_scene_error, e);
}

void bind_errors(py::module_& m) {
  static py::exception<Error> error(m, "Error", PyExc_ValueError);
  g_error = error.ptr();
  g_scene_error = PyErr_NewException("hapsim._hapsim.SceneError", g_error, nullptr);
  m.add_object("SceneError", py::handle(g_scene_error));
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) {
        std::rethrow_exception(p);
      }
    } catch (const Error& e) {
      set_error(g_error, e);
    }
  });
}

}  // namespace hapsim::python

namespace py = pybind11;
using namespace hapsim;
using namespace hapsim::python;

PYBIND11_MODULE(_hapsim, m) {
  m.doc() = "hapsim: real-time haptic simulation (docs/python.md)";
  bind_errors(m);

  py::class_<Scene>(m, "Scene", "A loaded scene file (load_scene)")
      .def_property_readonly("file", [](const Scene& s) { return s.description->file.string(); })
      .def_property_readonly("description",
                             [](const Scene& s) { return s.description->description; })
      .def_property_readonly("has_rig", [](const Scene& s) { return s.description->has_rig; })
      .def_property_readonly("warnings", [](const Scene& s) {
        py::list out;
        for (const std::string& w : s.description->warnings) {
          out.append(w);
        }
        return out;
      });
  m.def(
      "load_scene",
      [](const std::string& path, const std::optional<std::string>& data_dir) {
        return Scene{std::make_shared<const SceneDescription>(load(path, data_dir))};
      },
      py::arg("path"), py::arg("data_dir") = py::none(),
      "Loads a scene file; a bad one raises SceneError naming the file and JSON pointer.");
  m.def("run", &run, py::arg("scene"), py::arg("duration") = py::none(),
        py::arg("method") = py::none(), py::arg("record") = py::none(),
        py::arg("replay") = py::none(), py::arg("data_dir") = py::none(),
        "Runs a scene's own device to the end as fast as it goes (the GIL released) and returns "
        "the summary `hapsim run --json` writes, as a dict.");

  py::class_<PyRecording>(m, "Recording", "A session recording (read_recording)")
      .def("__len__", [](const PyRecording& r) { return r.recording.frames.size(); })
      .def_property_readonly("scene_hash",
                             [](const PyRecording& r) { return r.recording.header.scene_hash; })
      .def_property_readonly("time_s",
                             [](const py::object& self) {
                               return frame_view(
                                   self, 0, [](const RecordedFrame& f) { return &f.input.time_s; });
                             })
      .def_property_readonly("p_world",
                             [](const py::object& self) {
                               return frame_view(self, 3, [](const RecordedFrame& f) {
                                 return f.input.p_world.data();
                               });
                             })
      .def_property_readonly(
          "q_world",
          [](const PyRecording& r) {
            const auto& frames = r.recording.frames;
            py::array_t<double> a({static_cast<py::ssize_t>(frames.size()), py::ssize_t{4}});
            auto o = a.mutable_unchecked<2>();
            for (std::size_t i = 0; i < frames.size(); ++i) {
              const Quat& q = frames[i].input.q_world;
              const auto row = static_cast<py::ssize_t>(i);
              o(row, 0) = q.w();
              o(row, 1) = q.x();
              o(row, 2) = q.y();
              o(row, 3) = q.z();
            }
            return a;
          })
      .def_property_readonly("finger_rad",
                             [](const py::object& self) {
                               return frame_view(self, kMaxFingers, [](const RecordedFrame& f) {
                                 return f.input.finger_rad.data();
                               });
                             })
      .def_property_readonly("joint_rad",
                             [](const py::object& self) {
                               return frame_view(
                                   self, kMaxDeviceJoints,
                                   [](const RecordedFrame& f) { return f.input.joint_rad.data(); });
                             })
      .def_property_readonly("force_world_n",
                             [](const py::object& self) {
                               return frame_view(self, 3, [](const RecordedFrame& f) {
                                 return f.command.force_world_n.data();
                               });
                             })
      .def_property_readonly("finger_force_n",
                             [](const py::object& self) {
                               return frame_view(self, kMaxFingers, [](const RecordedFrame& f) {
                                 return f.command.finger_force_n.data();
                               });
                             })
      .def_property_readonly("joint_torque_nm",
                             [](const py::object& self) {
                               return frame_view(self, kMaxDeviceJoints,
                                                 [](const RecordedFrame& f) {
                                                   return f.command.joint_torque_nm.data();
                                                 });
                             })
      .def_property_readonly(
          "contact_count",
          [](const PyRecording& r) {
            py::array_t<std::int32_t> a(static_cast<py::ssize_t>(r.recording.frames.size()));
            auto o = a.mutable_unchecked<1>();
            for (std::size_t i = 0; i < r.recording.frames.size(); ++i) {
              o(static_cast<py::ssize_t>(i)) = r.recording.frames[i].contact_count;
            }
            return a;
          })
      .def(
          "input",
          [](const PyRecording& r, std::size_t i) {
            if (i >= r.recording.frames.size()) {
              throw py::index_error("frame " + std::to_string(i) + " of " +
                                    std::to_string(r.recording.frames.size()));
            }
            return r.recording.frames[i].input;
          },
          py::arg("frame"), "The device input of one frame, as recorded");
  m.def(
      "read_recording",
      [](const std::string& path) {
        py::gil_scoped_release release;
        return PyRecording{read_recording(path)};
      },
      py::arg("path"), "Reads a recording (hapsim run --record, World.record).");
  m.def(
      "compare_recordings",
      [](const std::string& expected, const std::string& actual) -> py::object {
        const RecordingDifference d =
            compare_recordings(read_recording(expected), read_recording(actual));
        if (d.identical) {
          return py::none();
        }
        return py::str(d.message);
      },
      py::arg("expected"), py::arg("actual"),
      "None when two recordings are identical bit for bit, else where they first differ.");

  bind_world(m);
  bind_geometry(m);
  bind_fem(m);
}
