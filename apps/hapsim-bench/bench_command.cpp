// `hapsim bench collision [--quick] [--json FILE] [--meshes ...] [--methods ...]`: point-query
// cost of hapsim's exact BVH, sphere tree and contact-radius query against CGAL, FCL and Embree
// on the same meshes and points (bench/collision_cases.h). `hapsim bench step`: the haptic step's
// cost per contact method (bench/step_cases.h). `hapsim bench network`: raw force against the
// local contact model over a simulated link (bench/link_sweep.h). `hapsim bench fem`: a FEM block's
// solver, the haptic step beside it and the local model's force error (bench/fem_cases.h).
// Progress on stderr, the table on stdout, rows as JSON on request.
#include "bench_commands.h"
#include "commands.h"
#include "json_output.h"
#include "network_dds_bench.h"
#include "progress_printer.h"
#include "stop_signal.h"

#include "bench/collision_cases.h"
#include "bench/contact_cases.h"
#include "bench/fem_cases.h"
#include "bench/link_sweep.h"
#include "bench/passivity_cases.h"
#include "bench/soak_cases.h"
#include "bench/step_cases.h"
#include "hapsim/core/data_dir.h"
#include "hapsim/core/stopwatch.h"
#include "hapsim/scene/scene_file.h"

#include <unistd.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace hapsim::app {
namespace {

struct BenchArgs {
  bool quick = false;
  std::string json_path;
  std::vector<std::string> meshes;
  std::vector<std::string> methods;
  std::vector<std::string> workloads;
  std::size_t queries = 0;
  std::string data_dir;
};

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) {
    out += (out.empty() ? "" : ", ") + n;
  }
  return out;
}

// A bench cut short by SIGINT or SIGTERM (each runner ends after the row under way): says so
// under the table of the rows it did, and sets the exit status 128 + the signal (130, 143). The
// JSON holds those rows (and, where it is an object, "stopped_by").
bool said_if_stopped(std::size_t rows) {
  if (!stop_requested().load(std::memory_order_relaxed)) {
    return false;
  }
  std::printf("stopped      by %s after %zu row(s): the table holds those\n", stop_signal_name(),
              rows);
  std::fflush(stdout);
  exit_status() = with_signal_status(exit_status());
  return true;
}

void run_collision(const BenchArgs& args) {
  bench::CollisionBenchOptions options;
  options.quick = args.quick;
  options.meshes = args.meshes;
  options.methods = args.methods;
  options.queries = args.queries;
  options.data_dir =
      args.data_dir.empty() ? bench::default_data_dir() : find_data_dir(args.data_dir);
  if (!args.data_dir.empty() && !options.data_dir) {
    throw CommandError("--data " + args.data_dir + ": not a folder");
  }
  const auto known_methods = bench::all_method_names();
  const auto built_methods = bench::available_methods();
  for (const auto& m : options.methods) {
    if (std::find(built_methods.begin(), built_methods.end(), m) == built_methods.end()) {
      throw CommandError(
          "--methods " + m + ": " +
          (std::find(known_methods.begin(), known_methods.end(), m) != known_methods.end()
               ? "not built in this binary"
               : "unknown method") +
          "; available: " + join(built_methods));
    }
  }
  const auto known_meshes = bench::all_collision_mesh_names();
  for (const auto& m : options.meshes) {
    if (std::find(known_meshes.begin(), known_meshes.end(), m) == known_meshes.end()) {
      throw CommandError("--meshes " + m + ": unknown mesh; expected one of " + join(known_meshes));
    }
  }
  if (!args.workloads.empty()) {
    options.workloads.clear();
    for (const auto& w : args.workloads) {
      options.workloads.push_back(w == "trajectory" ? bench::Workload::kTrajectory
                                                    : bench::Workload::kUniform);
    }
  }
  // Open the JSON file first, so a bad path fails before minutes of measuring.
  std::unique_ptr<AtomicFile> json_out;
  if (!args.json_path.empty()) {
    json_out = open_output("--json", args.json_path);
  }
  const std::vector<std::string> meshes =
      options.meshes.empty() ? bench::collision_mesh_names(options.quick, options.data_dir)
                             : options.meshes;
  std::cerr << "hapsim bench collision: meshes " << join(meshes) << "; methods "
            << join(options.methods.empty() ? built_methods : options.methods)
            << (options.data_dir ? "" : " (no data folder: knee meshes skipped)") << '\n';
  ProgressPrinter printer;
  options.progress = [&printer](std::string_view label, double fraction) {
    printer(label, fraction);
  };
  const Stopwatch watch;
  options.stop = &install_stop_signals();
  const std::vector<bench::CollisionRow> rows = bench::run_collision_bench(options);
  std::cout << bench::format_table(rows);

  // Short summary: hapsim's best closest-point method against the fastest library.
  std::cout << "\nSummary (median ratio to the fastest library; < 1 = hapsim faster):\n";
  std::size_t mismatched = 0;
  for (const auto& row : rows) {
    mismatched += row.mismatches;
    if (row.method == "hapsim-exact" || row.method == "hapsim-spheretree") {
      char line[160];
      std::snprintf(line, sizeof line, "  %-12s %-10s %-18s %6.2fx median  %6.2fx p99\n",
                    row.mesh.c_str(), row.workload.c_str(), row.method.c_str(),
                    row.ratio_to_fastest_library, row.p99_ratio_to_fastest_library);
      std::cout << line;
    }
  }
  std::cout << rows.size() << " rows in " << static_cast<int>(watch.elapsed_s()) << " s; "
            << (mismatched == 0 ? "every method agreed with the exact distances"
                                : std::to_string(mismatched) +
                                      " answers disagreed with the exact distances (see 'bad')")
            << '\n';
  if (json_out) {
    commit_output(*json_out, "--json", bench::rows_to_json(rows).dump(2) + '\n');
    std::cout << "wrote " << args.json_path << '\n';
  }
  if (mismatched != 0) {
    exit_status() = 1;
  }
  said_if_stopped(rows.size());
}

struct StepArgs {
  std::vector<std::string> methods;
  std::vector<std::string> scenes;
  std::string data_dir;
  double duration_s = 0.0;
  std::string json_path;
};

void run_step(const StepArgs& args) {
  std::unique_ptr<AtomicFile> json_out;
  if (!args.json_path.empty()) {
    json_out = open_output("--json", args.json_path);
  }
  bench::StepBenchOptions options;
  options.methods = args.methods;
  options.duration_s = args.duration_s;
  const std::optional<std::filesystem::path> data_dir =
      args.data_dir.empty() ? bench::default_data_dir()
                            : std::optional<std::filesystem::path>(args.data_dir);
  if (args.scenes.empty()) {
    options.cases = bench::default_step_cases(bench::default_scenes_dir(), data_dir);
    if (options.cases.size() < 3) {
      std::cerr << "hapsim bench step: no knee_vhf_left in the data folder: the 5-finger VHF "
                   "case is skipped (give --data)\n";
    }
  } else {
    for (const std::string& scene : args.scenes) {
      options.cases.push_back({std::filesystem::path(scene).stem().string(), scene, std::nullopt});
    }
  }
  ProgressPrinter printer;
  options.progress = [&printer](std::string_view label, double fraction) {
    printer(label, fraction);
  };
  options.stop = &install_stop_signals();
  const std::vector<bench::StepRow> rows = bench::run_step_bench(options);
  std::cout << bench::format_step_table(rows);
  std::cout << "step = device read + collision + force + deformation + safety + write, timed per "
               "cycle; ratios < 1: faster than the exact-query baseline\n";
  said_if_stopped(rows.size());
  if (json_out) {
    commit_output(*json_out, "--json", bench::step_rows_to_json(rows).dump(2) + '\n');
    std::cout << "wrote " << args.json_path << '\n';
  }
}

double load_average();

struct ContactArgs {
  std::vector<std::string> scenes;
  std::vector<std::string> methods;
  std::vector<double> speeds_mm_per_s;
  std::vector<std::string> landmarks;
  double press_n = 4.0;
  double max_depth_mm = 15.0;
  std::string json_path;
};

void run_contact(const ContactArgs& args) {
  JsonOutput json_out(args.json_path);
  bench::ContactBenchOptions options;
  for (const std::string& s : args.scenes) {
    options.scenes.emplace_back(s);
  }
  options.methods = args.methods;
  if (!args.speeds_mm_per_s.empty()) {
    options.speeds_mm_per_s = args.speeds_mm_per_s;
  }
  options.landmarks = args.landmarks;
  options.press_n = args.press_n;
  options.max_depth_mm = args.max_depth_mm;
  ProgressPrinter printer;
  options.progress = [&printer](std::string_view label, double fraction) {
    printer(label, fraction);
  };
  const Stopwatch watch;
  options.stop = &install_stop_signals();  // 8 minutes for the whole sweep
  const std::vector<bench::ContactRow> rows = bench::run_contact_bench(options);
  std::printf(
      "A fingertip pressed over each landmark until it pushes back %.1f N (at most %.0f mm past "
      "the skin), dragged 30 mm each way "
      "across it and back, then held 0.3 s; pops: pop-throughs (a proxy lost with the tool "
      "inside its body counts); jump: the largest force change between two cycles while "
      "dragging; peak and held: the force; step: World::step only (FEM updates between cycles, "
      "untimed)\n",
      args.press_n, args.max_depth_mm);
  std::cout << bench::format_contact_table(rows);
  std::size_t pops = 0;
  double worst_p99_us = 0.0;
  for (const bench::ContactRow& r : rows) {
    pops += r.pop_throughs;
    worst_p99_us = std::max(worst_p99_us, r.step_p99_us);
  }
  std::printf("%zu rows in %.1f s: %zu pop-throughs in all, worst step p99 %.1f us, load %.2f\n",
              rows.size(), watch.elapsed_s(), pops, worst_p99_us, load_average());
  const bool stopped = said_if_stopped(rows.size());
  if (json_out) {
    std::cout << std::flush;
    json_out.write({{"rows", bench::contact_rows_to_json(rows)},
                    {"press_n", args.press_n},
                    {"max_depth_mm", args.max_depth_mm},
                    {"load_average", load_average()},
                    {"stopped_by", stopped ? stop_signal_name() : ""}});
  }
}

struct PassivityArgs {
  std::vector<std::string> profiles;
  std::vector<std::string> surfaces;
  double device_mass_kg = 0.1;
  double hand_stiffness_n_per_m = 200.0;
  double hand_damping_n_s_per_m = 2.0;
  double hand_press_n = 1.0;
  int bisection_steps = 8;
  std::string json_path;
};

void run_passivity(const PassivityArgs& args) {
  JsonOutput json_out(args.json_path);
  bench::PassivityOptions options;
  options.profiles = args.profiles;
  options.surfaces = args.surfaces;
  options.scenes_dir = bench::default_scenes_dir();
  options.port.device_mass_kg = args.device_mass_kg;
  options.port.hand_stiffness_n_per_m = args.hand_stiffness_n_per_m;
  options.port.hand_damping_n_s_per_m = args.hand_damping_n_s_per_m;
  options.port.hand_press_n = args.hand_press_n;
  options.bisection_steps = args.bisection_steps;
  ProgressPrinter printer;
  options.progress = [&printer](std::string_view label, double fraction) {
    printer(label, fraction);
  };
  const Stopwatch watch;
  options.stop = &install_stop_signals();
  const bench::PassivityResult result = bench::run_passivity_sweep(options);
  char setup[400];
  std::snprintf(setup, sizeof setup,
                "Port: device %.3g kg, hand %.0f N/m and %.2g N s/m pressing %.2g N, 10 s from "
                "2 mm above; the world sampled at 1 kHz, its force held (ZOH), clamped to the "
                "profile's force (and rate)\n",
                args.device_mass_kg, args.hand_stiffness_n_per_m, args.hand_damping_n_s_per_m,
                args.hand_press_n);
  std::cout << setup
            << "E = work the rendered force did on the device + F^2/2K (<= 0 when passive); late: "
               "E's growth over the last 5 s; motion: peak to peak over the last second; stable: "
               "late <= 0.1 mJ and motion <= 0.1 mm\n";
  std::cout << bench::format_passivity_table(result);
  std::snprintf(setup, sizeof setup, "%zu runs in %.1f s\n", result.rows.size(), watch.elapsed_s());
  std::cout << setup;
  const bool stopped = said_if_stopped(result.rows.size());
  if (json_out) {
    std::cout << std::flush;
    nlohmann::json j = bench::passivity_to_json(result);
    j["stopped_by"] = stopped ? stop_signal_name() : "";
    json_out.write(j);
  }
}

struct FemArgs {
  std::vector<std::size_t> sizes;
  bool large = false;
  std::vector<std::string> elasticities;
  std::vector<double> speeds_mm_per_s;
  int steps = 200;
  double haptic_s = 2.0;
  double reference_spacing_mm = 0.1;
  double depth_mm = 6.0;
  bool no_error = false;
  std::string json_path;
};

// The 1-minute load average now ("-" when unknown): the machine is shared, the figures say so.
double load_average() {
  double load[1] = {-1.0};
  return getloadavg(load, 1) == 1 ? load[0] : -1.0;
}

void run_fem(const FemArgs& args) {
  JsonOutput json_out(args.json_path);
  bench::FemBenchOptions options;
  if (!args.sizes.empty()) {
    options.tet_counts = args.sizes;
  }
  if (args.large) {
    options.tet_counts.push_back(80000);  // factoring it takes long: on request
  }
  if (!args.elasticities.empty()) {
    options.elasticities.clear();
    for (const std::string& e : args.elasticities) {
      options.elasticities.push_back(e == "linear" ? FemElasticity::kLinear
                                                   : FemElasticity::kCorotational);
    }
  }
  if (!args.speeds_mm_per_s.empty()) {
    options.speeds_m_per_s.clear();
    for (const double v : args.speeds_mm_per_s) {
      options.speeds_m_per_s.push_back(1e-3 * v);
    }
  }
  options.fem_steps = args.steps;
  options.haptic_s = args.haptic_s;
  options.reference_spacing_m = 1e-3 * args.reference_spacing_mm;
  options.depth_m = 1e-3 * args.depth_mm;
  options.measure_error = !args.no_error;
  std::string sizes;
  for (const std::size_t n : options.tet_counts) {
    sizes += (sizes.empty() ? "" : ", ") + std::to_string(n);
  }
  const double load_before = load_average();
  std::cerr << "hapsim bench fem: about " << sizes << " tets; load average " << load_before << '\n';
  ProgressPrinter printer;
  options.progress = [&printer](std::string_view label, double fraction) {
    printer(label, fraction);
  };
  const Stopwatch watch;
  options.stop = &install_stop_signals();
  const bench::FemBenchResult result = bench::run_fem_bench(options);
  const double load_after = load_average();
  const bench::FemBlockSpec& b = result.block;
  char setup[600];
  std::snprintf(
      setup, sizeof setup,
      "Block %.0f x %.0f x %.0f mm (make_tet_block), bottom fixed; E %.0f kPa, nu %.2f, "
      "Rayleigh %.0f 1/s, %.2f s; contact %.0f N/m, %.1f N s/m, tool r %.0f mm, patch r "
      "%.0f mm\nFEM step: bare FemBody, backward Euler dt %.0f ms, one core, %d steps of a "
      "0-1-0 N press at 1 Hz; haptic step: World::step pressed %.1f mm sliding at 20 "
      "mm/s, FEM deferred (advance_fem between cycles, untimed), %.1f s\n",
      b.size_m.x() * 1e3, b.size_m.y() * 1e3, b.size_m.z() * 1e3,
      b.material.youngs_modulus_pa / 1e3, b.material.poisson_ratio, b.material.rayleigh_mass_per_s,
      b.material.rayleigh_stiffness_s, b.contact_stiffness_n_per_m, b.contact_damping_n_s_per_m,
      b.tool_radius_m * 1e3, b.patch_radius_m * 1e3, b.dt_s * 1e3, options.fem_steps,
      options.depth_m * 1e3, options.haptic_s);
  std::cout << setup << bench::format_fem_table(result);
  std::snprintf(setup, sizeof setup, "%zu rows in %.1f s; load average %.2f before, %.2f after\n",
                result.rows.size(), watch.elapsed_s(), load_before, load_after);
  std::cout << setup;
  const bool stopped = said_if_stopped(result.rows.size());
  if (json_out) {
    nlohmann::json j = bench::fem_bench_to_json(result);
    j["stopped_by"] = stopped ? stop_signal_name() : "";
    j["machine"] = {{"load_average_before", load_before},
                    {"load_average_after", load_after},
                    {"hardware_threads", sysconf(_SC_NPROCESSORS_ONLN)},
                    {"wall_s", watch.elapsed_s()}};
    std::cout << std::flush;
    json_out.write(j);
  }
}

struct SoakArgs {
  double minutes = 60.0;
  std::vector<std::string> scenes;
  std::string json_path;
};

void run_soak(const SoakArgs& args) {
  JsonOutput json_out(args.json_path);
  std::vector<std::string> scenes = args.scenes;
  if (scenes.empty()) {
    scenes = {(bench::default_scenes_dir() / "knee_paper.json").string(),
              (bench::default_scenes_dir() / "teleop.json").string()};
  }
  nlohmann::json rows = nlohmann::json::array();
  for (const std::string& scene : scenes) {
    bench::SoakOptions options;
    options.scene = scene;
    options.duration_s = args.minutes * 60.0;
    // A rig's pick-and-place moves the ball: each repetition starts from the scene's start.
    options.reset_between = load_scene(scene).has_rig;
    ProgressPrinter printer;
    options.progress = [&printer](std::string_view label, double fraction) {
      printer(label, fraction);
    };
    options.stop = &install_stop_signals();  // an hour's soak may be cut short: its JSON stays
    const bench::SoakResult result = bench::run_soak(options);
    std::cout << bench::format_soak(result) << std::flush;
    rows.push_back(bench::soak_to_json(result));
    if (result.stopped) {
      std::cout << "stopped      by " << stop_signal_name() << " after " << result.steps
                << " steps\n";
      break;
    }
  }
  if (json_out) {
    json_out.write(rows);
  }
  exit_status() = with_signal_status(exit_status());
}

struct NetworkArgs {
  bool quick = false;
  std::string json_path;
  std::vector<std::string> modes;
  std::vector<int> delays_ms;
  std::vector<double> losses_percent;
  std::uint64_t seed = 1;
  double approach_ms = 300.0;
  double blend_ms = 20.0;
  bool no_observer = false;
  // --dds: instead of the in-process sweep, the palpation over real Cyclone DDS on loopback
  // (network_dds_bench.h).
  bool dds = false;
  NetworkDdsArgs dds_args;
};

// Seconds as milliseconds for the table; "-" when not measured (negative).
std::string ms_or_dash(double seconds) {
  if (seconds < 0.0) {
    return "-";
  }
  char text[32];
  std::snprintf(text, sizeof text, "%.0f", 1e3 * seconds);
  return text;
}

std::string format_network_table(const std::vector<bench::LinkSweepRow>& rows) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "%-11s %-6s %-7s %5s %4s %6s | %8s %8s %8s %7s %9s %-6s %s\n",
                "mode", "env", "hand", "delay", "loss", "outage", "steady_N", "error_%", "ripple_N",
                "peak_N", "energy_mJ", "stable", "zero_ms (after last model)");
  out += line;
  for (const bench::LinkSweepRow& row : rows) {
    const bench::LinkCase& c = row.link_case;
    const std::string zero =
        row.is_outage() ? ms_or_dash(row.run.outage_force_zero_s) + " (" +
                              ms_or_dash(row.run.outage_force_zero_after_last_model_s) + ")"
                        : "-";
    std::snprintf(line, sizeof line,
                  "%-11s %-6s %-7s %5.0f %4.0f %6s | %8.3f %+8.2f %8.4f %7.2f %9.2f %-6s %s\n",
                  net::to_string(c.mode), bench::environment_name(c.environment),
                  bench::hand_name(c.hand), 1e3 * c.delay_s, 100.0 * c.loss,
                  row.is_outage() ? ms_or_dash(c.outage_s).c_str() : "-", row.run.steady_force_n,
                  100.0 * row.steady_force_error, row.run.hold_ripple_rms_n, row.run.peak_force_n,
                  1e3 * row.run.energy_generated_j, row.run.stable ? "yes" : "NO", zero.c_str());
    out += line;
  }
  return out;
}

nlohmann::json null_if_negative(double value) {
  return value < 0.0 ? nlohmann::json(nullptr) : nlohmann::json(value);
}

nlohmann::json network_rows_to_json(const std::vector<bench::LinkSweepRow>& rows) {
  nlohmann::json out = nlohmann::json::array();
  for (const bench::LinkSweepRow& row : rows) {
    const bench::LinkCase& c = row.link_case;
    const bench::LinkRun& r = row.run;
    out.push_back({
        {"mode", net::to_string(c.mode)},
        {"environment", bench::environment_name(c.environment)},
        {"hand", bench::hand_name(c.hand)},
        {"delay_ms", 1e3 * c.delay_s},
        {"jitter_max_ms", 1e3 * c.jitter_s},
        {"loss", c.loss},
        {"outage_ms", row.is_outage() ? 1e3 * c.outage_s : 0.0},
        {"approach_ms", 1e3 * c.approach_s},
        {"blend_ms", 1e3 * c.blend_s},
        {"passivity_observer", c.mode == net::ForceMode::kLocalModel && c.passivity_observer},
        {"seed", c.seed},
        {"duration_s", r.duration_s},
        {"energy_generated_j", r.energy_generated_j},
        {"energy_out_j", r.energy_out_j},
        {"steady_force_n", r.steady_force_n},
        {"steady_force_error", row.steady_force_error},
        {"reference_force_n", row.reference_force_n},
        {"analytic_force_n", row.analytic_force_n},
        {"hold_ripple_rms_n", r.hold_ripple_rms_n},
        {"peak_force_n", r.peak_force_n},
        {"hold_work_j", r.hold_work_j},
        {"stable", r.stable},
        {"outage_force_zero_s", null_if_negative(r.outage_force_zero_s)},
        {"outage_force_zero_after_last_model_s",
         null_if_negative(r.outage_force_zero_after_last_model_s)},
        {"passivity_acted_cycles", r.observer.acted},
        {"passivity_dissipated_j", r.observer.dissipated_j},
        {"models_accepted", r.models_accepted},
        {"refused_out_of_order", r.refused_out_of_order},
        {"lost", r.lost},
        {"reordered", r.reordered},
    });
  }
  return out;
}

// The targets for the local model, checked on every local-model row; what misses is
// printed with its figure.
std::vector<std::string> local_model_misses(const std::vector<bench::LinkSweepRow>& rows) {
  std::vector<std::string> misses;
  char line[256];
  for (const bench::LinkSweepRow& row : rows) {
    const bench::LinkCase& c = row.link_case;
    if (c.mode != net::ForceMode::kLocalModel) {
      continue;
    }
    std::snprintf(line, sizeof line,
                  "%s %s %.0f ms %.0f %%%s: ", bench::environment_name(c.environment),
                  bench::hand_name(c.hand), 1e3 * c.delay_s, 100.0 * c.loss,
                  row.is_outage() ? " outage" : "");
    const bench::LinkRun& r = row.run;
    std::string what;
    if (!r.stable) {
      what += "unstable; ";
    }
    char figure[96];
    if (std::abs(row.steady_force_error) > 0.05) {
      std::snprintf(figure, sizeof figure, "steady error %+.1f %%; ",
                    100.0 * row.steady_force_error);
      what += figure;
    }
    if (r.hold_ripple_rms_n >= 0.05) {
      std::snprintf(figure, sizeof figure, "ripple %.3f N rms; ", r.hold_ripple_rms_n);
      what += figure;
    }
    if (r.energy_generated_j >= 0.02) {
      std::snprintf(figure, sizeof figure, "energy %.1f mJ; ", 1e3 * r.energy_generated_j);
      what += figure;
    }
    if (row.is_outage() && !(r.outage_force_zero_after_last_model_s >= 0.0 &&
                             r.outage_force_zero_after_last_model_s <= 0.150 + 1e-9)) {
      what += "force not at zero 150 ms after the last model; ";
    }
    if (!what.empty()) {
      what.resize(what.size() - 2);  // the last "; "
      misses.push_back(line + what);
    }
  }
  return misses;
}

void run_network(const NetworkArgs& args) {
  if (args.dds) {
    NetworkDdsArgs dds = args.dds_args;
    dds.json_path = args.json_path;
    run_network_dds(dds);
    return;
  }
  std::unique_ptr<AtomicFile> json_out;
  if (!args.json_path.empty()) {
    json_out = open_output("--json", args.json_path);
  }
  bench::LinkSweepOptions options =
      args.quick ? bench::quick_link_sweep_options() : bench::LinkSweepOptions{};
  if (!args.modes.empty()) {
    options.modes.clear();
    for (const std::string& mode : args.modes) {
      options.modes.push_back(mode == "raw" ? net::ForceMode::kRaw : net::ForceMode::kLocalModel);
    }
  }
  if (!args.delays_ms.empty()) {
    options.delays_ms = args.delays_ms;
  }
  if (!args.losses_percent.empty()) {
    options.losses.clear();
    for (const double percent : args.losses_percent) {
      options.losses.push_back(percent / 100.0);
    }
  }
  options.seed = args.seed;
  options.approach_s = 1e-3 * args.approach_ms;
  options.blend_s = 1e-3 * args.blend_ms;
  options.passivity_observer = !args.no_observer;
  ProgressPrinter printer;
  options.progress = [&printer](std::string_view label, double fraction) {
    printer(label, fraction);
  };
  const Stopwatch watch;
  const std::vector<bench::LinkSweepRow> rows = bench::run_link_sweep(options);
  const double elapsed_s = watch.elapsed_s();
  std::cout << format_network_table(rows);
  std::cout << "1-DOF press, device 0.2 kg; jitter U[0, d/2]; error: steady force against the "
               "zero-delay run (raw: the analytic hold); ripple: rms over the last second; "
               "energy: max over the run of the work the force did on the device plus what the "
               "ideal environment holding that force would store; stable: ripple < 10 % of the "
               "hold and no net work fed in over the last second; zero_ms: outage start to "
               "|F| < 0.01 N for good ('-': raw holds its last force)\n";
  int raw_unstable = 0;
  int raw_rows = 0;
  for (const bench::LinkSweepRow& row : rows) {
    if (row.link_case.mode == net::ForceMode::kRaw && row.link_case.delay_s >= 0.005 &&
        !row.is_outage()) {
      ++raw_rows;
      raw_unstable += row.run.stable ? 0 : 1;
    }
  }
  char summary[160];
  std::snprintf(summary, sizeof summary, "%zu rows in %.1f s", rows.size(), elapsed_s);
  std::cout << summary;
  if (raw_rows > 0) {
    std::snprintf(summary, sizeof summary, "; raw unstable in %d of %d rows from 5 ms",
                  raw_unstable, raw_rows);
    std::cout << summary;
  }
  std::cout << '\n';
  const std::vector<std::string> misses = local_model_misses(rows);
  if (misses.empty()) {
    std::cout << "local model: every row stable, within 5 % of its zero-delay force, ripple < "
                 "0.05 N rms, energy < 20 mJ, outages at zero 150 ms after the last model\n";
  } else {
    std::cout << "local model misses its targets in " << misses.size() << " rows:\n";
    for (const std::string& miss : misses) {
      std::cout << "  " << miss << '\n';
    }
  }
  if (json_out) {
    commit_output(*json_out, "--json", network_rows_to_json(rows).dump(2) + '\n');
    std::cout << "wrote " << args.json_path << '\n';
  }
}

}  // namespace

void add_bench_subcommands(CLI::App& app) {
  CLI::App* bench = &app;
  auto args = std::make_shared<BenchArgs>();
  CLI::App* collision = bench->add_subcommand(
      "collision",
      "Closest-point query cost: hapsim's exact BVH, sphere tree and contact-radius query vs "
      "CGAL, FCL and Embree on the same meshes and points");
  collision->add_flag("--quick", args->quick,
                      "Fewer queries, no 1M-triangle mesh (about a minute)");
  collision->add_option("--json", args->json_path, "Write the rows as a JSON array to FILE");
  collision
      ->add_option(
          "--meshes", args->meshes,
          "Meshes to run (default: all for the mode): " + join(bench::all_collision_mesh_names()))
      ->delimiter(',');
  collision
      ->add_option("--methods", args->methods,
                   "Methods to run (default: all built): " + join(bench::available_methods()))
      ->delimiter(',');
  collision->add_option("--workloads", args->workloads, "trajectory, uniform (default: both)")
      ->delimiter(',')
      ->check(CLI::IsMember({"trajectory", "uniform"}));
  collision
      ->add_option("--queries", args->queries,
                   "Timed queries per row (default 20000, --quick 4000)")
      ->check(CLI::PositiveNumber);
  collision->add_option("--data", args->data_dir,
                        "Real-data folder for the knee meshes (default: $HAPSIM_DATA or "
                        "../shared/data)");
  collision->callback([args] { run_collision(*args); });

  auto step_args = std::make_shared<StepArgs>();
  CLI::App* step = bench->add_subcommand("step",
                                         "Haptic step cost on the knee scenes (one fingertip; five "
                                         "on the FEM knee and the real knee) per contact "
                                         "method, beside the exact-query baseline");
  step->add_option("--methods", step_args->methods, "exact, spheretree, knee (default: all)")
      ->delimiter(',')
      ->check(CLI::IsMember({"exact", "spheretree", "knee"}));
  step->add_option("--scenes", step_args->scenes,
                   "Scene files to run instead of the shipped knee scenes")
      ->delimiter(',');
  step->add_option("--data", step_args->data_dir,
                   "Real-data folder holding knee_vhf_left (default: $HAPSIM_DATA or "
                   "../shared/data)");
  step->add_option("--duration", step_args->duration_s,
                   "Simulated seconds per run (default: the whole palpation)")
      ->check(positive_seconds());
  step->add_option("--json", step_args->json_path, "Write the rows as a JSON array to FILE");
  step->callback([step_args] { run_step(*step_args); });

  auto passivity_args = std::make_shared<PassivityArgs>();
  CLI::App* passivity = bench->add_subcommand(
      "passivity",
      "Energy generated at the device port: every device profile at 1.0x and 1.5x its rated "
      "stiffness on a plane, a sphere, the sheet, the knee and a FEM block, held by a simulated "
      "device and hand; the largest stable stiffness (Z-width) beside the rating");
  passivity->add_option("--profiles", passivity_args->profiles, "Device profiles (default: all)")
      ->delimiter(',');
  passivity
      ->add_option("--surfaces", passivity_args->surfaces,
                   "plane, sphere, sheet, knee, fem, fem_knee (default: all but fem_knee, "
                   "whose 26k-tet factorisation makes each run slow)")
      ->delimiter(',')
      ->check(CLI::IsMember({"plane", "sphere", "sheet", "knee", "fem", "fem_knee"}));
  passivity
      ->add_option("--device-mass", passivity_args->device_mass_kg,
                   "The device's apparent mass at the handle, kg (default 0.1: no profile states "
                   "one)")
      ->check(CLI::Range(1e-3, 100.0));
  passivity
      ->add_option("--hand-stiffness", passivity_args->hand_stiffness_n_per_m,
                   "The hand's spring, N/m (default 200)")
      ->check(CLI::Range(1.0, 1e5));
  passivity
      ->add_option("--hand-damping", passivity_args->hand_damping_n_s_per_m,
                   "The hand's damper, N s/m (default 2)")
      ->check(CLI::Range(0.0, 1e3));
  passivity
      ->add_option("--hand-press", passivity_args->hand_press_n,
                   "How hard the hand presses at rest, N (default 1)")
      ->check(CLI::Range(0.01, 100.0));
  passivity
      ->add_option("--bisection-steps", passivity_args->bisection_steps,
                   "Bisection steps for the Z-width (default 8; 0: none)")
      ->check(CLI::Range(0, 30));
  passivity->add_option("--json", passivity_args->json_path, "Write the rows as JSON to FILE");
  passivity->callback([passivity_args] { run_passivity(*passivity_args); });

  add_snapshot_bench(*bench);

  auto contact_args = std::make_shared<ContactArgs>();
  CLI::App* contact = bench->add_subcommand(
      "contact",
      "Contact at hand speed: a fingertip pressed over the knee's landmarks (patella, tibial "
      "tuberosity, patellar tendon, MCL, LCL) dragged across them at 10-500 mm/s, per scene and "
      "contact method: pop-throughs, force continuity and the step's cost");
  contact
      ->add_option("--scenes", contact_args->scenes,
                   "Scene files (default: scenes/knee_paper.json, knee.json and thin_plate.json)")
      ->delimiter(',');
  contact->add_option("--methods", contact_args->methods, "exact, spheretree, knee (default: all)")
      ->delimiter(',')
      ->check(CLI::IsMember({"exact", "spheretree", "knee"}));
  contact
      ->add_option("--speeds", contact_args->speeds_mm_per_s,
                   "Drag speeds, mm/s (default 10,50,200,500)")
      ->delimiter(',')
      ->check(CLI::Range(0.1, 5000.0));
  contact
      ->add_option("--landmarks", contact_args->landmarks,
                   "Landmarks (default: all): " + join(bench::contact_landmark_names()))
      ->delimiter(',');
  contact
      ->add_option("--press", contact_args->press_n,
                   "Press in until the fingertip pushes back this much, N (default 4)")
      ->check(CLI::Range(0.1, 50.0));
  contact
      ->add_option("--max-depth-mm", contact_args->max_depth_mm,
                   "... or this far past the first touch of the skin, mm (default 15)")
      ->check(CLI::Range(0.0, 50.0));
  contact->add_option("--json", contact_args->json_path, "Write the rows as JSON to FILE");
  contact->callback([contact_args] { run_contact(*contact_args); });

  auto fem_args = std::make_shared<FemArgs>();
  CLI::App* fem = bench->add_subcommand(
      "fem",
      "A FEM block (80 x 60 x 30 mm, bottom fixed) per tet count, linear and corotational: the "
      "solver's step rate on one core, factorisation time and memory, the haptic step with the "
      "block in contact, and the 1 kHz local model's force error against a full solve along a "
      "palpation");
  fem->add_option("--sizes", fem_args->sizes, "Approximate tet counts (default 1000,5000,20000)")
      ->delimiter(',')
      ->check(CLI::Range(std::size_t{6}, std::size_t{2000000}));
  fem->add_flag("--large", fem_args->large, "Add the 80k-tet block (its factorisation takes long)");
  fem->add_option("--elasticity", fem_args->elasticities, "linear, corotational (default: both)")
      ->delimiter(',')
      ->check(CLI::IsMember({"linear", "corotational"}));
  fem->add_option("--speeds", fem_args->speeds_mm_per_s,
                  "Palpation speeds for the force error, mm/s (default 10,50,200)")
      ->delimiter(',')
      ->check(CLI::Range(0.1, 2000.0));
  fem->add_option("--steps", fem_args->steps, "Timed FEM steps per row (default 200)")
      ->check(CLI::Range(1, 100000));
  fem->add_option("--haptic-seconds", fem_args->haptic_s,
                  "Timed haptic steps per row, simulated s (default 2)")
      ->check(CLI::Range(0.01, 600.0));
  fem->add_option("--reference-spacing", fem_args->reference_spacing_mm,
                  "Path length between full solves, mm (default 0.1; linear in between)")
      ->check(CLI::Range(0.001, 5.0));
  fem->add_option("--depth", fem_args->depth_mm,
                  "How deep the palpation presses beyond the first touch, mm (default 6)")
      ->check(CLI::Range(0.1, 15.0));
  fem->add_flag("--no-error", fem_args->no_error, "Skip the local model's force error");
  fem->add_option("--json", fem_args->json_path, "Write the rows as JSON to FILE");
  fem->callback([fem_args] { run_fem(*fem_args); });

  auto soak_args = std::make_shared<SoakArgs>();
  CLI::App* soak = bench->add_subcommand(
      "soak",
      "An hour of simulated time, fast-forward, of the knee palpation and the teleoperation "
      "script repeated: step cost and peak RSS per minute, force drift between repetitions");
  soak->add_option("--minutes", soak_args->minutes, "Simulated minutes per scene (default 60)")
      ->check(CLI::Range(0.1, 1440.0));
  soak->add_option("--scenes", soak_args->scenes,
                   "Scene files (default: scenes/knee_paper.json and scenes/teleop.json)")
      ->delimiter(',');
  soak->add_option("--json", soak_args->json_path, "Write the results as JSON to FILE");
  soak->callback([soak_args] { run_soak(*soak_args); });

  auto network_args = std::make_shared<NetworkArgs>();
  CLI::App* network = bench->add_subcommand(
      "network",
      "Raw force vs the local contact model over a simulated link: a 1-DOF press on tissue and on "
      "a wall, delay x loss x jitter, plus a 300 ms outage (no network needed)");
  network->add_flag("--quick", network_args->quick,
                    "Delays 0, 20, 100 ms and losses 0, 30 % only (a few seconds)");
  network->add_option("--json", network_args->json_path, "Write the rows as a JSON array to FILE");
  network->add_option("--modes", network_args->modes, "raw, local-model (default: both)")
      ->delimiter(',')
      ->check(CLI::IsMember({"raw", "local-model"}));
  network
      ->add_option("--delays", network_args->delays_ms,
                   "One-way delays, ms (default 0,5,20,50,100)")
      ->delimiter(',')
      ->check(CLI::Range(0, 1000));
  network->add_option("--losses", network_args->losses_percent, "Loss rates, % (default 0,10,30)")
      ->delimiter(',')
      ->check(CLI::Range(0.0, 100.0));
  network->add_option("--seed", network_args->seed, "Seed of the links' draws (default 1)");
  network->add_option(
      "--approach", network_args->approach_ms,
      "The hand's approach to its target, ms (minimum jerk; 0: a step; default 300)");
  network->add_option("--blend", network_args->blend_ms,
                      "The device's blend time for a new model, ms (default 20)");
  network->add_flag("--no-observer", network_args->no_observer,
                    "Run the local model without its passivity observer (for comparison)");
  network->add_flag("--dds", network_args->dds,
                    "Instead: serve, device and viewers as processes over real Cyclone DDS on "
                    "loopback (round trip, loop timing with and without --viewers)");
  network
      ->add_option("--viewers", network_args->dds_args.viewers,
                   "--dds: viewers (hapsim watch) in the second run (default 8)")
      ->check(CLI::Range(0, 24));
  network
      ->add_option("--duration", network_args->dds_args.duration_s,
                   "--dds: seconds per run (default 10.5: the knee's palpation)")
      ->check(CLI::Range(1.0, 600.0));
  network->add_option("--scene", network_args->dds_args.scene,
                      "--dds: the scene served (default scenes/knee_procedural.json)");
  network->add_flag(
      "--secure", network_args->dds_args.secure_compare,
      "--dds: only the probe, plain and then with DDS Security (domain and domain+1): "
      "round trip and a participant's join time, each way");
  network->add_option("--domain", network_args->dds_args.domain, "--dds: DDS domain id")
      ->check(CLI::Range(0, 232));
  network->callback([network_args] { run_network(*network_args); });
}

}  // namespace hapsim::app
