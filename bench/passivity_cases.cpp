#include "bench/passivity_cases.h"

#include "bench/fem_cases.h"
#include "hapsim/core/device_profile.h"
#include "hapsim/core/error.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/world/world.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <memory>
#include <sstream>

namespace hapsim::bench {

PortRun run_port(const PortEnvironment& environment, double stiffness_n_per_m,
                 const PortOptions& options) {
  const double m = options.device_mass_kg;
  const double k_h = options.hand_stiffness_n_per_m;
  const double b_h = options.hand_damping_n_s_per_m;
  // The hand's anchor: at rest it presses with hand_press_n on a spring of the rendered stiffness.
  const double s_anchor = -options.hand_press_n / stiffness_n_per_m - options.hand_press_n / k_h;
  const int samples = static_cast<int>(std::lround(options.duration_s / options.sample_period_s));
  const double h = options.sample_period_s / options.substeps;
  const int half = samples / 2;
  const int last_second = samples - static_cast<int>(std::lround(1.0 / options.sample_period_s));

  double s = options.start_gap_m;
  double v = 0.0;
  double work_j = 0.0;
  double f = 0.0;
  double energy_half_j = 0.0;
  double s_min = s;
  double s_max = s;
  PortRun run;
  const auto energy = [&](double force_n) {
    return work_j + force_n * force_n / (2.0 * stiffness_n_per_m);
  };
  for (int k = 0; k < samples; ++k) {
    const double t0 = k * options.sample_period_s;
    f = environment(s, t0);
    for (int i = 0; i < options.substeps; ++i) {
      const double s_before = s;
      const double f_before = f;
      const double a = (f - k_h * (s - s_anchor) - b_h * v) / m;
      v += a * h;
      s += v * h;
      if (options.zero_order_hold) {
        work_j += f * (s - s_before);  // exact: f is held over the sample
      } else {
        f = environment(s, t0 + (i + 1) * h);
        work_j += 0.5 * (f_before + f) * (s - s_before);  // exact for a linear spring
      }
    }
    run.peak_force_n = std::max(run.peak_force_n, std::abs(f));
    run.energy_max_j = std::max(run.energy_max_j, energy(f));
    if (k == half) {
      energy_half_j = energy(f);
    }
    if (k >= last_second) {
      s_min = std::min(s_min, s);
      s_max = std::max(s_max, s);
    } else {
      s_min = s_max = s;
    }
    if (!std::isfinite(s) || std::abs(s) > 1.0) {
      // Thrown out of the workspace: unstable beyond doubt.
      run.energy_end_j = run.energy_max_j = std::numeric_limits<double>::infinity();
      run.late_energy_j = run.late_motion_m = std::numeric_limits<double>::infinity();
      run.final_depth_m = -s;
      return run;
    }
  }
  run.energy_end_j = energy(f);
  run.late_energy_j = run.energy_end_j - energy_half_j;
  run.late_motion_m = s_max - s_min;
  run.final_depth_m = -s;
  run.stable = run.late_energy_j <= options.late_energy_threshold_j &&
               run.late_motion_m <= options.late_motion_threshold_m;
  return run;
}

namespace {

constexpr double kToolRadiusM = 0.003;
// The search for the Z-width: from 1/64 to 64 times the rating.
constexpr double kSearchFactor = 64.0;

std::string number(double x) {
  char text[64];
  std::snprintf(text, sizeof text, "%.9g", x);
  return text;
}

// The scene text of one probe surface: a plane (the top of a box) or a sphere, rendered by a god
// object with a plastic's shipped damping (scenes/csg_block.json), or the virtual sheet with its
// contact spring's (scenes/hand_ball_sheet.json). The sheet must be stiffer than its contact
// spring (the loader refuses a press that would not settle): twice as stiff here.
std::string surface_scene(const std::string& surface, double stiffness_n_per_m, double max_force_n,
                          const std::string& profile) {
  const bool sheet = surface == "sheet";
  std::string body;
  if (surface == "plane") {
    body = R"({"name": "plane", "type": "static", "pose": {"position_m": [0, 0, -0.02]},
               "geometry": {"box": {"half_extents_m": [0.1, 0.1, 0.02]}},
               "materials": {"default": "surface"}})";
  } else if (surface == "sphere") {
    body = R"({"name": "sphere", "type": "static", "pose": {"position_m": [0, 0, -0.05]},
               "geometry": {"sphere": {"radius_m": 0.05}}, "materials": {"default": "surface"}})";
  } else {
    body = R"({"name": "sheet", "type": "deformable", "deformation": "sheet",
               "pose": {"position_m": [0, 0, 0]},
               "geometry": {"sheet": {"nodes_per_side": 32, "size_m": 0.2}},
               "sheet": {"sensitivity_n_per_mm": )" +
           number(2.0 * stiffness_n_per_m / 1000.0) +
           R"(, "cutoff_radius_mm": 44.0, "width_mm": 40.1},
               "materials": {"default": "surface"}})";
  }
  return R"({"format": "hapsim-scene/1", "world": {"name": "passivity-)" + surface +
         R"("}, "materials": {"surface": {"response": ")" + (sheet ? "penalty" : "proxy") +
         R"(", "stiffness_n_per_m": )" + number(stiffness_n_per_m) +
         R"(, "max_penetration_m": 0.05, "max_force_n": )" + number(max_force_n) +
         R"(, "damping_n_s_per_m": )" + (sheet ? "2.0" : "1.0") + R"(}}, "bodies": [)" + body +
         R"(], "tools": [{"name": "tip", "radius_m": )" + number(kToolRadiusM) +
         R"(, "finger": -1}], "device": {"type": "simulated", "profile": ")" + profile +
         R"(", "palpation": {"targets": [{"body": ")" + surface + R"(", "segment": ")" + surface +
         R"(", "from": [0, 0, 1], "depth_m": 0.001, "hold_s": 0.1}]}}})";
}

// Where the port presses: the first touch along the approach and the outward normal there.
struct PortLine {
  Vec3 p_touch_world = Vec3::Zero();
  Vec3 n_world = Vec3::UnitZ();
};

// Steps the world along p_start − n·s in 0.05 mm steps until it pushes back; then resets it.
PortLine find_touch(World& world, const Vec3& p_start, const Vec3& n_world) {
  constexpr double kStepM = 5e-5;
  DeviceInput input;
  for (int i = 0; i < 4000; ++i) {
    input.time_s = i * 1e-3;
    input.p_world = p_start - n_world * (i * kStepM);
    const StepResult& result = world.step(input, 1e-3);
    if (result.command.force_world_n.norm() > 0.0) {
      world.reset();
      return {p_start - n_world * ((i - 1) * kStepM), n_world};
    }
  }
  world.reset();
  throw Error("passivity sweep", "the probe never touched " + world.description().name);
}

// The knee: where the shipped palpation (scenes/knee_procedural.json) first touches, along the
// force it felt there.
PortLine knee_touch(const SceneDescription& knee) {
  RunSetup setup = make_run_setup(knee, DeviceChoice::scene_script());
  const double dt = knee.run.dt_s > 0.0 ? knee.run.dt_s : 1e-3;
  for (double t = 0.0; t < setup.duration_s; t += dt) {
    const DeviceInput input = setup.device->read(t);
    const StepResult& result = setup.world->step(input, dt);
    const Vec3 f = result.command.force_world_n;
    if (f.norm() > 0.05) {
      const Vec3 n = f.normalized();
      return {input.p_world, n};
    }
  }
  throw Error(knee.file.string(), "the palpation never touches the knee");
}

struct Surface {
  std::string name;
  std::function<std::unique_ptr<World>(const DeviceProfile&, double k)> build;
  PortLine line;
  /// The stiffness of the energy's storage term F²/2K when it is not the material's k (a FEM
  /// body renders its contact spring in series with the tissue): from a world built for k.
  std::function<double(World&, const PortLine&, double k)> port_stiffness;
};

// The FEM block of `hapsim bench fem` (scenes/fem_block.json's block and material), about 1k
// tets, corotational, backward Euler at 100 Hz: the world steps its FEM update itself (inline),
// so the port sees the one-period latency of the coupling and the local model in between.
FemBlockSpec passivity_fem_block() {
  FemBlockSpec spec;
  spec.cells = fem_block_cells(spec.size_m, 1000);
  return spec;
}

// What the FEM world renders along the port's normal: the stiffness of the local model adopted
// with the tool held 0.5 mm beyond the first touch (the contact spring in series with the
// tissue's condensed compliance there). Smaller than k, so F²/2K counts more stored energy than
// F²/2k would: E is not made to look passive by the tissue's give.
double fem_port_stiffness(World& world, const PortLine& line, double k) {
  DeviceInput input;
  input.p_world = line.p_touch_world - line.n_world * 5e-4;
  for (int i = 0; i < 50; ++i) {
    input.time_s = i * 1e-3;
    (void)world.step(input, 1e-3);
  }
  if (world.state().fem_contacts.empty()) {
    return k;
  }
  const LocalContactModel& m = world.state().fem_contacts[0].model;
  const double k_n = m.normal_world.dot(m.stiffness_n_per_m * m.normal_world);
  return m.valid && std::isfinite(k_n) && k_n > 0.0 ? std::min(k_n, k) : k;
}

double limit_n(const DeviceProfile& profile) {
  // A glove has no tip actuator: its finger actuator pushes on the pressing finger.
  return profile.max_force_n > 0.0 ? profile.max_force_n : profile.max_finger_force_n;
}

// A scene's world with every material's spring at the swept stiffness and the device's limit.
auto scene_at_stiffness(const std::shared_ptr<const SceneDescription>& scene) {
  return [scene](const DeviceProfile& profile, double k) {
    WorldDescription world = scene->world;
    for (MaterialDescription& m : world.materials) {
      m.contact.stiffness_n_per_m = k;
      m.contact.max_force_n = limit_n(profile);
    }
    return std::make_unique<World>(std::move(world));
  };
}

// The port's environment: the world at the handle's pose, its force clamped to the device's
// rating (and rate), along the port's normal.
PortEnvironment world_port(World& world, const PortLine& line, const DeviceProfile& profile,
                           double sample_period_s) {
  auto last_push = std::make_shared<double>(0.0);
  return [&world, line, &profile, sample_period_s, last_push](double s_m, double t_s) {
    DeviceInput input;
    input.time_s = t_s;
    input.p_world = line.p_touch_world + line.n_world * s_m;
    Vec3 f = world.step(input, sample_period_s).command.force_world_n;
    const double limit = limit_n(profile);
    if (!f.allFinite()) {
      f.setZero();
    } else if (f.norm() > limit) {
      f *= limit / f.norm();
    }
    double push = f.dot(line.n_world);
    if (profile.max_force_rate_n_per_s) {
      const double step = *profile.max_force_rate_n_per_s * sample_period_s;
      push = std::clamp(push, *last_push - step, *last_push + step);
    }
    *last_push = push;
    return push;
  };
}

}  // namespace

PassivityResult run_passivity_sweep(const PassivityOptions& options) {
  std::vector<const DeviceProfile*> profiles;
  if (options.profiles.empty()) {
    for (const DeviceProfile& p : builtin_device_profiles()) {
      profiles.push_back(&p);
    }
  } else {
    for (const std::string& name : options.profiles) {
      profiles.push_back(&device_profile(name));
    }
  }
  std::vector<std::string> surface_names = options.surfaces;
  if (surface_names.empty()) {
    surface_names = {"plane", "sphere", "sheet", "knee", "fem"};
  }

  std::vector<Surface> surfaces;
  for (const std::string& name : surface_names) {
    if (name == "knee") {
      auto knee = std::make_shared<SceneDescription>(
          load_scene(options.scenes_dir / "knee_procedural.json"));
      Surface s{name, scene_at_stiffness(knee), knee_touch(*knee), {}};
      surfaces.push_back(std::move(s));
    } else if (name == "plane" || name == "sphere" || name == "sheet") {
      Surface s{name,
                [name](const DeviceProfile& profile, double k) {
                  const SceneDescription scene =
                      parse_scene(surface_scene(name, k, limit_n(profile), profile.name),
                                  "passivity-" + name + ".json");
                  return std::make_unique<World>(scene.world);
                },
                {},
                {}};
      // Every built-in surface's top is at the origin, facing +z.
      const DeviceProfile& any = builtin_device_profiles().front();
      std::unique_ptr<World> probe = s.build(any, any.max_stiffness_n_per_m);
      s.line = find_touch(*probe, Vec3(0.0, 0.0, 0.02), Vec3::UnitZ());
      surfaces.push_back(std::move(s));
    } else if (name == "fem") {
      Surface s{name,
                [](const DeviceProfile& profile, double k) {
                  FemBlockSpec spec = passivity_fem_block();
                  spec.contact_stiffness_n_per_m = k;
                  spec.max_force_n = limit_n(profile);
                  return std::make_unique<World>(fem_block_world(spec));
                },
                {},
                fem_port_stiffness};
      // The block's top is at z = its height, centred in x and y.
      const DeviceProfile& any = builtin_device_profiles().front();
      std::unique_ptr<World> probe = s.build(any, any.max_stiffness_n_per_m);
      s.line = find_touch(*probe, Vec3(0.0, 0.0, passivity_fem_block().size_m.z() + 0.02),
                          Vec3::UnitZ());
      surfaces.push_back(std::move(s));
    } else if (name == "fem_knee") {
      // The FEM knee (scenes/knee.json) over the patella: 5 mm of FEM tissue on a rigid
      // bone, every material's spring at the swept stiffness and the device's force limit.
      auto knee = std::make_shared<SceneDescription>(load_scene(options.scenes_dir / "knee.json"));
      Surface s{name, scene_at_stiffness(knee), {}, fem_port_stiffness};
      const DeviceProfile& any = builtin_device_profiles().front();
      std::unique_ptr<World> probe = s.build(any, any.max_stiffness_n_per_m);
      s.line = find_touch(*probe, Vec3(-0.01, 0.09, 0.028), Vec3::UnitY());
      surfaces.push_back(std::move(s));
    } else {
      throw Error("--surfaces", "unknown surface '" + name +
                                    "', expected plane, sphere, sheet, knee, fem or fem_knee");
    }
  }

  PassivityResult result;
  const double total = static_cast<double>(profiles.size() * surfaces.size());
  std::size_t done = 0;
  for (const DeviceProfile* profile : profiles) {
    for (const Surface& surface : surfaces) {
      if (options.stop != nullptr && options.stop->load(std::memory_order_relaxed)) {
        return result;
      }
      const auto port_stiffness = [&](double k) {
        return surface.port_stiffness
                   ? surface.port_stiffness(*surface.build(*profile, k), surface.line, k)
                   : k;
      };
      const auto run_at = [&](double k) {
        const double k_port = port_stiffness(k);
        std::unique_ptr<World> world = surface.build(*profile, k);
        const PortEnvironment env =
            world_port(*world, surface.line, *profile, options.port.sample_period_s);
        return run_port(env, k_port, options.port);
      };
      const double rated = profile->max_stiffness_n_per_m;
      for (const double factor : {1.0, 1.5}) {
        result.rows.push_back({profile->name, surface.name, rated, factor,
                               options.port.device_mass_kg, run_at(factor * rated)});
        result.rows.back().port_stiffness_n_per_m = port_stiffness(factor * rated);
      }
      if (options.bisection_steps > 0) {
        ZWidthRow z{profile->name, surface.name, rated, 0.0, false};
        double lo = std::log(rated / kSearchFactor);
        double hi = std::log(rated * kSearchFactor);
        if (run_at(std::exp(hi)).stable) {
          z.max_stable_stiffness_n_per_m = std::exp(hi);
          z.above_search = true;
        } else if (run_at(std::exp(lo)).stable) {
          for (int i = 0; i < options.bisection_steps; ++i) {
            const double mid = 0.5 * (lo + hi);
            (run_at(std::exp(mid)).stable ? lo : hi) = mid;
          }
          z.max_stable_stiffness_n_per_m = std::exp(lo);
        }
        result.z_width.push_back(z);
      }
      ++done;
      report_progress(options.progress, profile->name + " " + surface.name,
                      static_cast<double>(done) / total);
    }
  }
  return result;
}

std::string format_passivity_table(const PassivityResult& result) {
  std::ostringstream out;
  char line[256];
  std::snprintf(line, sizeof line, "%-16s %-7s %10s %6s %12s %12s %11s %10s %9s %s\n", "profile",
                "surface", "rated N/m", "x", "E end mJ", "E max mJ", "late mJ", "motion mm",
                "peak N", "stable");
  out << line;
  for (const PassivityRow& r : result.rows) {
    std::snprintf(line, sizeof line,
                  "%-16s %-7s %10.0f %6.1f %12.4f %12.4f %11.4f %10.4f %9.2f %s\n",
                  r.profile.c_str(), r.surface.c_str(), r.rated_stiffness_n_per_m, r.factor,
                  r.run.energy_end_j * 1e3, r.run.energy_max_j * 1e3, r.run.late_energy_j * 1e3,
                  r.run.late_motion_m * 1e3, r.run.peak_force_n, r.run.stable ? "yes" : "NO");
    out << line;
  }
  bool noted = false;
  for (const PassivityRow& r : result.rows) {
    if (r.port_stiffness_n_per_m > 0.0 &&
        r.port_stiffness_n_per_m != r.factor * r.rated_stiffness_n_per_m) {
      if (!noted) {
        out << "K in F^2/2K where it is not the material's (the FEM block: its contact spring in "
               "series with the tissue, as rendered 0.5 mm in):\n";
        noted = true;
      }
      std::snprintf(line, sizeof line, "  %-16s %-7s %4.1fx: k %.0f N/m, K %.1f N/m\n",
                    r.profile.c_str(), r.surface.c_str(), r.factor,
                    r.factor * r.rated_stiffness_n_per_m, r.port_stiffness_n_per_m);
      out << line;
    }
  }
  if (!result.z_width.empty()) {
    out << "\nZ-width: the largest stable stiffness (bisection between 1/64 and 64x the rating)\n";
    std::snprintf(line, sizeof line, "%-16s %-7s %10s %14s %8s\n", "profile", "surface",
                  "rated N/m", "max stable N/m", "x rated");
    out << line;
    for (const ZWidthRow& z : result.z_width) {
      std::snprintf(line, sizeof line, "%-16s %-7s %10.0f %13.0f%s %8.2f\n", z.profile.c_str(),
                    z.surface.c_str(), z.rated_stiffness_n_per_m, z.max_stable_stiffness_n_per_m,
                    z.above_search ? "+" : " ",
                    z.max_stable_stiffness_n_per_m / z.rated_stiffness_n_per_m);
      out << line;
    }
  }
  return out.str();
}

nlohmann::json passivity_to_json(const PassivityResult& result) {
  nlohmann::json rows = nlohmann::json::array();
  const auto finite_or_null = [](double x) -> nlohmann::json {
    return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
  };
  for (const PassivityRow& r : result.rows) {
    rows.push_back({{"profile", r.profile},
                    {"surface", r.surface},
                    {"rated_stiffness_n_per_m", r.rated_stiffness_n_per_m},
                    {"stiffness_factor", r.factor},
                    {"device_mass_kg", r.device_mass_kg},
                    {"port_stiffness_n_per_m", r.port_stiffness_n_per_m},
                    {"energy_end_j", finite_or_null(r.run.energy_end_j)},
                    {"energy_max_j", finite_or_null(r.run.energy_max_j)},
                    {"late_energy_j", finite_or_null(r.run.late_energy_j)},
                    {"late_motion_m", finite_or_null(r.run.late_motion_m)},
                    {"final_depth_m", finite_or_null(r.run.final_depth_m)},
                    {"peak_force_n", r.run.peak_force_n},
                    {"stable", r.run.stable}});
  }
  nlohmann::json z = nlohmann::json::array();
  for (const ZWidthRow& r : result.z_width) {
    z.push_back({{"profile", r.profile},
                 {"surface", r.surface},
                 {"rated_stiffness_n_per_m", r.rated_stiffness_n_per_m},
                 {"max_stable_stiffness_n_per_m", r.max_stable_stiffness_n_per_m},
                 {"above_search", r.above_search}});
  }
  return {{"rows", rows}, {"z_width", z}};
}

}  // namespace hapsim::bench
