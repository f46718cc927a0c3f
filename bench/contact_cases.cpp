#include "bench/contact_cases.h"

#include "bench/step_cases.h"
#include "hapsim/core/error.h"
#include "hapsim/core/statistics.h"
#include "hapsim/core/stopwatch.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace hapsim::bench {
namespace {

struct Landmark {
  const char* scene;  ///< the scene file's stem it belongs to, or a prefix of it ("knee")
  const char* name;
  Vec3 point_world;  ///< the anatomy, scene frame (x medial, y anterior, z proximal)
  Vec3 from;         ///< where the fingertip comes from
  Vec3 across;       ///< the drag's direction: across the structure
};

// The knee scenes' landmarks (scenes/knee.json's palpation targets), and the middle of
// scenes/thin_plate.json's 2 mm plate.
const Landmark kLandmarks[] = {
    {"knee", "patella", {-0.01, 0.054, 0.028}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}},
    {"knee", "tibial tuberosity", {-0.005, 0.014, -0.047}, {0.0, 1.0, -0.35}, {1.0, 0.0, 0.0}},
    {"knee", "patellar tendon", {-0.0157, 0.0327, -0.0162}, {0.0, 1.0, 0.0}, {1.0, 0.0, 0.0}},
    {"knee", "MCL", {0.0364, -0.0022, -0.0061}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}},
    {"knee", "LCL", {-0.0428, -0.027, -0.0065}, {-1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}},
    {"thin_plate", "2 mm plate", {0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, {1.0, 0.0, 0.0}},
};

ContactMethod method_named(const std::string& name) {
  if (const auto m = parse_contact_method(name)) {
    return *m;
  }
  throw Error("--methods", "unknown method '" + name + "', expected exact, spheretree or knee");
}

struct Drive {
  explicit Drive(World& w) : world(w), fem(w.fem() != nullptr) {}
  World& world;
  bool fem = false;
  std::vector<double> step_us;
  std::vector<double> jumps_n;
  std::size_t pop_throughs = 0;
  double peak_n = 0.0;
  Vec3 last_force = Vec3::Zero();

  const StepResult& step(const Vec3& p_world, bool timed, bool dragging) {
    DeviceInput in;
    in.p_world = p_world;
    const Stopwatch watch;
    const StepResult& r = world.step(in, 1e-3);
    const double us = watch.elapsed_s() * 1e6;
    if (fem) {
      world.advance_fem();  // between cycles, untimed (hapsim run: the FEM thread)
    }
    if (timed) {
      step_us.push_back(us);
    }
    const Vec3 f = r.command.force_world_n;
    if (dragging) {
      jumps_n.push_back((f - last_force).norm());
    }
    last_force = f;
    peak_n = std::max(peak_n, f.norm());
    pop_throughs += static_cast<std::size_t>(std::max(0, r.penalty_pop_throughs));
    return r;
  }
  void go(const Vec3& a, const Vec3& b, double speed_m_per_s, bool dragging) {
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / speed_m_per_s / 1e-3)));
    for (int i = 1; i <= n; ++i) {
      (void)step(a + (b - a) * (static_cast<double>(i) / n), true, dragging);
    }
  }
};

ContactRow run_case(const SceneDescription& scene, const std::string& scene_name,
                    const std::string& method, const Landmark& lm, double speed_mm_per_s,
                    double press_n, double max_depth_m) {
  ContactRow row;
  row.scene = scene_name;
  row.landmark = lm.name;
  row.method = method;
  row.speed_mm_per_s = speed_mm_per_s;
  RunSetupOptions setup_options;
  setup_options.method = method_named(method);
  RunSetup setup;
  try {
    setup = make_run_setup(scene, DeviceChoice::scene_script(), setup_options);
  } catch (const Error& e) {
    row.error = e.what();
    return row;
  }
  World& world = *setup.world;
  Drive drive(world);
  world.set_fem_deferred(drive.fem);
  const Vec3 from = lm.from.normalized();
  const Vec3 across = lm.across.normalized();
  // In from 60 mm out: fast to the first touch, then slowly until it pushes back firmly.
  double s = 0.06;
  double touched = std::nan("");
  while (s > -0.05) {
    const StepResult& r = drive.step(lm.point_world + from * s, false, false);
    const double push_n = r.command.force_world_n.dot(from);
    if (std::isnan(touched) && push_n > 0.02) {
      touched = s;
    }
    if (!std::isnan(touched) && (push_n >= press_n || touched - s >= max_depth_m)) {
      break;
    }
    s -= (std::isnan(touched) ? 0.05 : 0.01) * 1e-3;
  }
  if (std::isnan(touched)) {
    row.error = "never touched the skin";
    return row;
  }
  row.depth_mm = (touched - s) * 1e3;
  const Vec3 centre = lm.point_world + from * s;
  const double v = speed_mm_per_s * 1e-3;
  drive.go(centre, centre + across * 0.03, v, true);
  drive.go(centre + across * 0.03, centre - across * 0.03, v, true);
  drive.go(centre - across * 0.03, centre, v, true);
  for (int i = 0; i < 300; ++i) {
    (void)drive.step(centre, true, false);
  }
  row.held_force_n = drive.last_force.norm();
  row.steps = drive.step_us.size();
  row.pop_throughs = drive.pop_throughs;
  row.peak_force_n = drive.peak_n;
  row.max_force_jump_n =
      drive.jumps_n.empty() ? 0.0 : *std::max_element(drive.jumps_n.begin(), drive.jumps_n.end());
  row.p99_force_jump_n = nearest_rank_percentile(drive.jumps_n, 0.99);
  row.step_p50_us = nearest_rank_percentile(drive.step_us, 0.50);
  row.step_p99_us = nearest_rank_percentile(drive.step_us, 0.99);
  row.step_max_us = *std::max_element(drive.step_us.begin(), drive.step_us.end());
  return row;
}

}  // namespace

std::vector<std::string> contact_landmark_names() {
  std::vector<std::string> out;
  for (const Landmark& l : kLandmarks) {
    out.emplace_back(l.name);
  }
  return out;
}

std::vector<ContactRow> run_contact_bench(const ContactBenchOptions& options) {
  std::vector<std::filesystem::path> scenes = options.scenes;
  if (scenes.empty()) {
    scenes = {default_scenes_dir() / "knee_paper.json", default_scenes_dir() / "knee.json",
              default_scenes_dir() / "thin_plate.json"};
  }
  std::vector<std::string> methods = options.methods;
  if (methods.empty()) {
    methods = {"exact", "spheretree", "knee"};
  }
  for (const std::string& name : options.landmarks) {
    if (std::none_of(std::begin(kLandmarks), std::end(kLandmarks),
                     [&](const Landmark& l) { return name == l.name; })) {
      throw Error("--landmarks", "unknown landmark '" + name + "'");
    }
  }
  // The landmarks of a scene: those named (all by default) that belong to it.
  const auto landmarks_of = [&](const std::string& stem) {
    std::vector<const Landmark*> out;
    for (const Landmark& l : kLandmarks) {
      const bool named = options.landmarks.empty() ||
                         std::find(options.landmarks.begin(), options.landmarks.end(), l.name) !=
                             options.landmarks.end();
      if (named && stem.rfind(l.scene, 0) == 0) {
        out.push_back(&l);
      }
    }
    return out;
  };
  std::size_t cases = 0;
  for (const std::filesystem::path& file : scenes) {
    cases += landmarks_of(file.stem().string()).size();
  }
  if (cases == 0) {
    throw Error("--landmarks",
                "no landmark given belongs to the scenes given (the knee's: "
                "knee*.json; the plate's: thin_plate.json)");
  }
  std::vector<ContactRow> rows;
  const double total = static_cast<double>(cases * methods.size() * options.speeds_mm_per_s.size());
  for (const std::filesystem::path& file : scenes) {
    const std::vector<const Landmark*> landmarks = landmarks_of(file.stem().string());
    if (landmarks.empty()) {
      continue;
    }
    const SceneDescription scene = load_scene(file);
    for (const std::string& method : methods) {
      for (const Landmark* lm : landmarks) {
        for (const double speed : options.speeds_mm_per_s) {
          if (options.stop != nullptr && options.stop->load(std::memory_order_relaxed)) {
            return rows;
          }
          report_progress(options.progress,
                          file.stem().string() + " / " + method + " / " + lm->name,
                          static_cast<double>(rows.size()) / total);
          rows.push_back(run_case(scene, file.stem().string(), method, *lm, speed, options.press_n,
                                  options.max_depth_mm * 1e-3));
        }
      }
    }
  }
  report_progress(options.progress, "done", 1.0);
  return rows;
}

std::string format_contact_table(const std::vector<ContactRow>& rows) {
  std::ostringstream out;
  char line[400];
  std::snprintf(line, sizeof line,
                "%-10s %-18s %-10s %6s %6s %6s %5s %9s %9s %7s %7s %8s %8s %8s\n", "scene",
                "landmark", "method", "mm/s", "depth", "steps", "pops", "jump max", "jump p99",
                "peak", "held", "p50 us", "p99 us", "max us");
  out << line;
  for (const ContactRow& r : rows) {
    if (!r.error.empty()) {
      std::snprintf(line, sizeof line, "%-10s %-18s %-10s %6.0f  ", r.scene.c_str(),
                    r.landmark.c_str(), r.method.c_str(), r.speed_mm_per_s);
      out << line << r.error << '\n';
      continue;
    } else {
      std::snprintf(line, sizeof line,
                    "%-10s %-18s %-10s %6.0f %3.1f mm %6zu %5zu %7.2f N %7.2f N %5.2f N %5.2f N "
                    "%8.2f %8.2f %8.1f\n",
                    r.scene.c_str(), r.landmark.c_str(), r.method.c_str(), r.speed_mm_per_s,
                    r.depth_mm, r.steps, r.pop_throughs, r.max_force_jump_n, r.p99_force_jump_n,
                    r.peak_force_n, r.held_force_n, r.step_p50_us, r.step_p99_us, r.step_max_us);
    }
    out << line;
  }
  return out.str();
}

nlohmann::json contact_rows_to_json(const std::vector<ContactRow>& rows) {
  nlohmann::json out = nlohmann::json::array();
  for (const ContactRow& r : rows) {
    nlohmann::json j{{"scene", r.scene},
                     {"landmark", r.landmark},
                     {"method", r.method},
                     {"speed_mm_per_s", r.speed_mm_per_s}};
    if (!r.error.empty()) {
      j["error"] = r.error;
    } else {
      j.update({{"depth_mm", r.depth_mm},
                {"steps", r.steps},
                {"pop_throughs", r.pop_throughs},
                {"max_force_jump_n", r.max_force_jump_n},
                {"p99_force_jump_n", r.p99_force_jump_n},
                {"peak_force_n", r.peak_force_n},
                {"held_force_n", r.held_force_n},
                {"step_p50_us", r.step_p50_us},
                {"step_p99_us", r.step_p99_us},
                {"step_max_us", r.step_max_us}});
    }
    out.push_back(j);
  }
  return out;
}

}  // namespace hapsim::bench
