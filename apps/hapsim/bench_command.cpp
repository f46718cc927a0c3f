// `hapsim bench collision [--quick] [--json FILE] [--meshes ...] [--methods ...]`: point-query
// cost of hapsim's exact BVH, sphere tree and contact-radius query against CGAL, FCL and Embree
// on the same meshes and points (bench/collision_cases.h). Progress on stderr, the table on
// stdout, rows as JSON on request.
#ifdef HAPSIM_WITH_BENCH

#include "commands.h"
#include "progress_printer.h"

#include "bench/collision_cases.h"
#include "bench/step_cases.h"
#include "hapsim/core/data_dir.h"
#include "hapsim/core/stopwatch.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
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
  std::unique_ptr<std::ofstream> json_out;
  if (!args.json_path.empty()) {
    json_out = std::make_unique<std::ofstream>(args.json_path);
    if (!*json_out) {
      throw CommandError("--json " + args.json_path + ": cannot open for writing");
    }
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
    *json_out << bench::rows_to_json(rows).dump(2) << '\n';
    if (!*json_out) {
      throw CommandError("--json " + args.json_path + ": write failed");
    }
    std::cout << "wrote " << args.json_path << '\n';
  }
  if (mismatched != 0) {
    exit_status() = 1;
  }
}

struct StepArgs {
  std::vector<std::string> methods;
  std::vector<std::string> scenes;
  std::string data_dir;
  double duration_s = 0.0;
  std::string json_path;
};

void run_step(const StepArgs& args) {
  std::unique_ptr<std::ofstream> json_out;
  if (!args.json_path.empty()) {
    json_out = std::make_unique<std::ofstream>(args.json_path);
    if (!*json_out) {
      throw CommandError("--json " + args.json_path + ": cannot open for writing");
    }
  }
  bench::StepBenchOptions options;
  options.methods = args.methods;
  options.duration_s = args.duration_s;
  const std::optional<std::filesystem::path> data_dir =
      args.data_dir.empty() ? bench::default_data_dir()
                            : std::optional<std::filesystem::path>(args.data_dir);
  if (args.scenes.empty()) {
    options.cases = bench::default_step_cases(bench::default_scenes_dir(), data_dir);
    if (options.cases.size() < 2) {
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
  const std::vector<bench::StepRow> rows = bench::run_step_bench(options);
  std::cout << bench::format_step_table(rows);
  std::cout << "step = device read + collision + force + deformation + safety + write, timed per "
               "cycle; ratios < 1: faster than the exact-query baseline\n";
  if (json_out) {
    *json_out << bench::step_rows_to_json(rows).dump(2) << '\n';
    if (!*json_out) {
      throw CommandError("--json " + args.json_path + ": write failed");
    }
    std::cout << "wrote " << args.json_path << '\n';
  }
}

}  // namespace

void add_bench_command(CLI::App& app) {
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks (tables on stdout, JSON on request)");
  bench->require_subcommand(1);
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
  CLI::App* step = bench->add_subcommand(
      "step",
      "Haptic step cost on the knee scenes (one fingertip; five on the real knee) per contact "
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
      ->check(CLI::PositiveNumber);
  step->add_option("--json", step_args->json_path, "Write the rows as a JSON array to FILE");
  step->callback([step_args] { run_step(*step_args); });
}

}  // namespace hapsim::app

#endif  // HAPSIM_WITH_BENCH
