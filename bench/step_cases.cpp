#include "bench/step_cases.h"

#include "hapsim/collision/knee_error.h"
#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/core/error.h"
#include "hapsim/runtime/session.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/world/world.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

namespace hapsim::bench {
namespace {

ContactMethod method_from_name(const std::string& name) {
  if (const auto m = parse_contact_method(name)) {
    return *m;
  }
  throw Error("--methods", "unknown method '" + name + "', expected exact, spheretree or knee");
}

}  // namespace

std::filesystem::path default_scenes_dir() {
  return HAPSIM_BENCH_SCENES_DIR;
}

std::vector<StepBenchCase> default_step_cases(
    const std::filesystem::path& scenes_dir, const std::optional<std::filesystem::path>& data_dir) {
  std::vector<StepBenchCase> cases;
  cases.push_back({"knee-1-finger", scenes_dir / "knee_procedural.json", std::nullopt});
  // The FEM knee (the default scene) under five fingertips: five contacts on one FEM body.
  cases.push_back({"fem-knee-5-fingers", scenes_dir / "knee_fem_five_fingers.json", std::nullopt});
  if (data_dir && std::filesystem::is_directory(*data_dir / "knee_vhf_left")) {
    cases.push_back({"vhf-5-fingers", scenes_dir / "knee_vhf.json", *data_dir / "knee_vhf_left"});
  }
  return cases;
}

std::vector<StepRow> run_step_bench(const StepBenchOptions& options) {
  std::vector<std::string> methods = options.methods;
  if (methods.empty()) {
    methods = {"exact", "spheretree", "knee"};
  }
  // Exact first: the other rows are compared with it.
  std::stable_partition(methods.begin(), methods.end(),
                        [](const std::string& m) { return m == "exact"; });
  std::vector<StepRow> rows;
  const double total = static_cast<double>(options.cases.size() * methods.size());
  std::size_t done = 0;
  for (const StepBenchCase& c : options.cases) {
    SceneLoadOptions load;
    if (c.data_dir) {
      load.data_dir = *c.data_dir;
    }
    const SceneDescription scene = load_scene(c.scene, load);
    const StepRow* exact_row = nullptr;
    std::size_t first_row = rows.size();
    for (const std::string& method : methods) {
      report_progress(options.progress, c.name + " / " + method, static_cast<double>(done) / total);
      RunSetupOptions setup_options;
      setup_options.method = method_from_name(method);
      RunSetup setup = make_run_setup(scene, DeviceChoice::scene_script(), setup_options);
      const World& world = *setup.world;
      SessionOptions session;
      session.dt_s = scene.run.dt_s;
      session.duration_s = options.duration_s > 0.0 ? options.duration_s : setup.duration_s;
      session.stop = options.stop;
      const SessionSummary s = run_session(*setup.world, *setup.device, session);
      if (s.interrupted) {
        return rows;  // cut short: not a row
      }

      StepRow row;
      row.case_name = c.name;
      row.method = method;
      row.tools = world.description().tools.size();
      row.segments = world.flat_segment_count();
      for (const BodyDescription& b : world.description().bodies) {
        for (const SegmentDescription& seg : b.segments) {
          row.vertices += seg.mesh.vertex_count();
        }
      }
      row.steps = s.steps;
      row.build_ms = world.build_ms();
      row.memory_bytes = world.query_memory_bytes();
      row.p50_us = s.step_us.p50;
      row.p99_us = s.step_us.p99;
      row.max_us = s.step_us.max;
      row.mean_us = s.step_us.mean;
      for (const ToolSummary& t : s.tools) {
        row.contact_steps += t.contact_steps;
        row.peak_force_n = std::max(row.peak_force_n, t.peak_force_n);
      }
      row.pop_throughs = s.pop_throughs;
      if (method != "exact") {
        // The method's error against the exact query on each segment's rest surface, the one
        // the step uses (outside the timed run).
        std::size_t contacts = 0;
        std::size_t misses = 0;
        row.error_p95_m = 0.0;
        row.error_max_m = 0.0;
        for (std::size_t b = 0; b < world.body_count(); ++b) {
          for (std::size_t seg = 0; seg < world.segment_count(b); ++seg) {
            const TriangleMesh& mesh = world.description().bodies[b].segments[seg].mesh;
            const MeshBvh exact(mesh);
            const std::vector<Vec3> points =
                sample_surface_band(mesh, kErrorPointsPerSegment, 0.005);
            const ApproximationError e =
                measure_approximation_error(world.rest_query(b, seg), exact, points, 0.005);
            row.error_p95_m = std::max(row.error_p95_m, e.p95_abs_error_m);
            row.error_max_m = std::max(row.error_max_m, e.max_abs_error_m);
            contacts += e.reference_contacts;
            misses += e.misses;
          }
        }
        row.error_miss_rate =
            contacts > 0 ? static_cast<double>(misses) / static_cast<double>(contacts) : 0.0;
      }
      rows.push_back(row);
      ++done;
    }
    for (std::size_t i = first_row; i < rows.size(); ++i) {
      if (rows[i].method == "exact") {
        exact_row = &rows[i];
      }
    }
    if (exact_row != nullptr) {
      for (std::size_t i = first_row; i < rows.size(); ++i) {
        rows[i].p50_ratio_to_exact = rows[i].p50_us / exact_row->p50_us;
        rows[i].p99_ratio_to_exact = rows[i].p99_us / exact_row->p99_us;
      }
    }
  }
  report_progress(options.progress, "done", 1.0);
  return rows;
}

std::string format_step_table(const std::vector<StepRow>& rows) {
  std::ostringstream out;
  char line[320];
  std::snprintf(line, sizeof line, "%-15s %-11s %5s %8s %7s %9s %8s %8s %8s %8s %9s %9s %8s %5s\n",
                "case", "method", "tools", "vertices", "steps", "build_ms", "mem_MB", "p50_us",
                "p99_us", "max_us", "p50/exact", "p99/exact", "contact", "pops");
  out << line;
  for (const StepRow& r : rows) {
    std::snprintf(
        line, sizeof line,
        "%-15s %-11s %5zu %8zu %7zu %9.1f %8.2f %8.2f %8.2f %8.1f %9.2f %9.2f %8zu %5zu\n",
        r.case_name.c_str(), r.method.c_str(), r.tools, r.vertices, r.steps, r.build_ms,
        static_cast<double>(r.memory_bytes) / 1e6, r.p50_us, r.p99_us, r.max_us,
        r.p50_ratio_to_exact, r.p99_ratio_to_exact, r.contact_steps, r.pop_throughs);
    out << line;
  }
  bool any_error = false;
  for (const StepRow& r : rows) {
    if (r.error_p95_m < 0.0) {
      continue;
    }
    if (!any_error) {
      std::snprintf(line, sizeof line,
                    "error vs exact (%zu points per segment within 5 mm of its surface):\n",
                    kErrorPointsPerSegment);
      out << line;
      any_error = true;
    }
    std::snprintf(line, sizeof line,
                  "  %-15s %-11s worst segment p95 %.3f mm, max %.3f mm, missed contacts %.2f %%\n",
                  r.case_name.c_str(), r.method.c_str(), r.error_p95_m * 1e3, r.error_max_m * 1e3,
                  100.0 * r.error_miss_rate);
    out << line;
  }
  return out.str();
}

nlohmann::json step_rows_to_json(const std::vector<StepRow>& rows) {
  nlohmann::json j = nlohmann::json::array();
  for (const StepRow& r : rows) {
    j.push_back({{"case", r.case_name},
                 {"method", r.method},
                 {"tools", r.tools},
                 {"segments", r.segments},
                 {"vertices", r.vertices},
                 {"steps", r.steps},
                 {"build_ms", r.build_ms},
                 {"memory_bytes", r.memory_bytes},
                 {"step_us",
                  {{"p50", r.p50_us}, {"p99", r.p99_us}, {"max", r.max_us}, {"mean", r.mean_us}}},
                 {"p50_ratio_to_exact", r.p50_ratio_to_exact},
                 {"p99_ratio_to_exact", r.p99_ratio_to_exact},
                 {"contact_steps", r.contact_steps},
                 {"pop_throughs", r.pop_throughs},
                 {"peak_force_n", r.peak_force_n}});
    if (r.error_p95_m >= 0.0) {
      j.back()["error_vs_exact"] = {{"worst_segment_p95_m", r.error_p95_m},
                                    {"max_m", r.error_max_m},
                                    {"miss_rate", r.error_miss_rate}};
    }
  }
  return j;
}

}  // namespace hapsim::bench
