// `hapsim calibrate glove RAW.csv --procedure PROC.json --out USER.json`: fits a user's glove
// calibration (device/glove_calibration.h, docs/glove-calibration.md) to a recorded procedure and
// prints each joint's residual; a calibration that fits badly is refused (exit 2, one line naming
// the sensor or joint) and nothing is written to --out.
#include "checked_output.h"
#include "commands.h"

#include "hapsim/core/error.h"
#include "hapsim/device/glove_calibration.h"
#include "hapsim/scene/glove_calibration_file.h"
#include "hapsim/script/trajectory.h"

#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>

namespace hapsim::app {
namespace {

struct CalibrateGloveArgs {
  std::string raw_path;
  std::string procedure_path;
  std::string out_path;
  std::string json_path;
  GloveFitOptions options;
};

void run_calibrate_glove(const CalibrateGloveArgs& args) {
  // Checked here, not by CLI11's Range: "nan" passes a range check.
  if (!(args.options.max_residual_deg > 0.0 && args.options.max_residual_deg <= 90.0)) {
    throw CommandError("--max-residual-deg: expected degrees in (0, 90], got " +
                       std::to_string(args.options.max_residual_deg));
  }
  if (!(args.options.min_sensor_range_counts >= 0.0 &&
        args.options.min_sensor_range_counts <= 1e6)) {
    throw CommandError("--min-range-counts: expected counts in [0, 1e6], got " +
                       std::to_string(args.options.min_sensor_range_counts));
  }
  const Trajectory raw = load_trajectory_csv(args.raw_path);
  const GloveProcedure procedure = load_glove_procedure(args.procedure_path);
  GloveCalibration c;
  try {
    c = fit_glove_calibration(raw, procedure, args.options, args.raw_path);
  } catch (const Error& e) {
    if (!args.json_path.empty()) {
      write_json_file("--json", args.json_path, {{"refused", true}, {"error", e.what()}});
    }
    throw;
  }
  std::printf("calibration  %s: %zu rows, %zu poses, %zu held samples, layout %s\n",
              args.raw_path.c_str(), raw.size(), procedure.poses.size(), c.held_samples,
              c.layout.c_str());
  std::printf("%-22s %-38s %8s %8s\n", "joint", "sensor", "rms_deg", "max_deg");
  double worst_rms = 0.0;
  for (const GloveJointResidual& r : c.residuals) {
    std::printf("%-22s %-38s %8.3f %8.3f\n", glove_joint_label(r.joint).c_str(),
                glove_sensor_label(r.sensor).c_str(), r.rms_deg, r.max_deg);
    worst_rms = std::max(worst_rms, r.rms_deg);
  }
  std::printf("%-22s not measured (held at 0: the spread sensors measure from the middle finger)\n",
              glove_joint_label(kGloveUnmeasuredJoint).c_str());
  const Vec3 p_mm = c.p_tracker_hand * 1e3;
  if (c.palm_offset_fitted) {
    std::printf("tracker→hand pivot fit: [%.1f, %.1f, %.1f] mm, %.2f mm RMS over %zu rows\n",
                p_mm.x(), p_mm.y(), p_mm.z(), c.pivot_rms_m * 1e3, c.pivot_samples);
  } else {
    std::printf("tracker→hand given: [%.1f, %.1f, %.1f] mm (the procedure has no pivot)\n",
                p_mm.x(), p_mm.y(), p_mm.z());
  }
  const nlohmann::json user = glove_calibration_json(c, args.raw_path, args.procedure_path);
  write_json_file("--out", args.out_path, user);
  std::printf("written      %s (worst joint %.3f deg RMS, limit %g)\n", args.out_path.c_str(),
              worst_rms, args.options.max_residual_deg);
  if (!args.json_path.empty()) {
    nlohmann::json report = {{"refused", false},
                             {"worst_rms_deg", worst_rms},
                             {"max_residual_deg", args.options.max_residual_deg},
                             {"calibration", user}};
    write_json_file("--json", args.json_path, report);
  }
}

}  // namespace

void add_calibrate_command(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand(
      "calibrate", "Fit a device's per-user calibration from a recorded procedure");
  cmd->require_subcommand(1);
  auto args = std::make_shared<CalibrateGloveArgs>();
  CLI::App* glove = cmd->add_subcommand(
      "glove",
      "Raw glove sensor counts -> the hand model's joint angles (docs/glove-calibration.md): "
      "prints each joint's residual, writes USER.json for a glove device's \"calibration\"");
  glove
      ->add_option("raw", args->raw_path,
                   "The recorded procedure: t,x,y,z,qw,qx,qy,qz,s0..s13 (tracker pose, counts)")
      ->required();
  glove
      ->add_option("--procedure", args->procedure_path,
                   "PROC.json: the poses held and when, the pivot (or a given offset)")
      ->required();
  glove->add_option("--out", args->out_path, "Write the calibration (USER.json) here")->required();
  glove->add_option("--json", args->json_path, "Also write a report as JSON (also when refused)");
  glove->add_option("--max-residual-deg", args->options.max_residual_deg,
                    "Refuse a joint whose RMS residual is above this (default 5)");
  glove->add_option("--min-range-counts", args->options.min_sensor_range_counts,
                    "A sensor spanning fewer counts over the recording is dead (default 8)");
  glove->callback([args] { run_calibrate_glove(*args); });
}

}  // namespace hapsim::app
