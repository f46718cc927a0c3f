// `hapsim sheet-profile SCENE --out FILE.csv`: the virtual sheet's Gaussian deformation model
// (seed 000 §3.2.2, Fig. 3) sampled by the model's own code, for plots: the profile z(d, F) the
// sheet sums (GaussianSheetProfile::depth_m) at fine steps of the distance from a contact, and
// the depth of every node of the scene's sheet grid (VirtualSheet) under one push at its centre.
#include "checked_output.h"
#include "commands.h"

#include "hapsim/core/error.h"
#include "hapsim/deform/sheet_profile.h"
#include "hapsim/deform/virtual_sheet.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"

#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

namespace hapsim::app {
namespace {

struct SheetProfileArgs {
  std::string scene;
  std::string out_path;
  std::vector<double> forces_n = {1.0, 2.0, 4.0};
};

void run_sheet_profile(const SheetProfileArgs& args) {
  for (const double f : args.forces_n) {
    if (!(f >= 0.0) || !(f < 1e6)) {
      throw CommandError("--force: expected newtons in [0, 1e6), got " + std::to_string(f));
    }
  }
  OutputFile out_file("--out", args.out_path);
  std::FILE* out = out_file.get();
  // The sheet as the run builds it (a teleoperation rig adds its sheet as a body).
  const RunSetup setup = make_run_setup(load_scene(args.scene), DeviceChoice::scene_script());
  const WorldDescription& d = setup.world->description();
  const BodyDescription* sheet_body = nullptr;
  for (const BodyDescription& b : d.bodies) {
    if (b.kind == BodyKind::kDeformable && b.deformation == BodyDeformation::kGaussianSheet) {
      sheet_body = &b;
      break;
    }
  }
  if (sheet_body == nullptr) {
    throw CommandError(args.scene + ": no virtual sheet (a body with deformation \"sheet\")");
  }
  const GaussianSheetParams& p = sheet_body->sheet_profile;
  const GaussianSheetProfile profile(p);
  if (!out_file.is_stdout()) {
    std::printf(
        "sheet        %s '%s': %dx%d nodes over %.0f mm; d0 %.1f mm, xi %.1f mm, F0 %.2f N/mm\n",
        args.scene.c_str(), sheet_body->name.c_str(), sheet_body->sheet.nodes_per_side,
        sheet_body->sheet.nodes_per_side, sheet_body->sheet.side_m * 1e3, p.cutoff_radius_m * 1e3,
        p.width_m * 1e3, p.sensitivity_n_per_m * 1e-3);
  }
  std::fprintf(out,
               "# hapsim sheet-profile %s: d0_mm=%.6g xi_mm=%.6g F0_n_per_mm=%.6g nodes=%d "
               "side_mm=%.6g\n",
               args.scene.c_str(), p.cutoff_radius_m * 1e3, p.width_m * 1e3,
               p.sensitivity_n_per_m * 1e-3, sheet_body->sheet.nodes_per_side,
               sheet_body->sheet.side_m * 1e3);
  std::fprintf(out, "kind,force_n,distance_mm,depth_mm\n");
  const double reach_m = 1.25 * p.cutoff_radius_m;
  for (const double f : args.forces_n) {
    // The model: z(d, F) every 0.25 mm.
    const int steps = static_cast<int>(std::floor(reach_m / 2.5e-4 + 1e-9));
    for (int k = 0; k <= steps; ++k) {
      const double d_m = 2.5e-4 * k;
      std::fprintf(out, "profile,%.6g,%.6g,%.9g\n", f, d_m * 1e3, profile.depth_m(d_m, f) * 1e3);
    }
    // The grid: one push at the centre of a fresh sheet of the scene's size.
    VirtualSheet sheet(sheet_body->sheet, std::make_unique<GaussianSheetProfile>(p));
    const std::array<SheetContact, 1> push{SheetContact{Vec3::Zero(), f}};
    sheet.apply_contacts(push);
    const int n = sheet.nodes_per_side();
    const std::span<const double> z = sheet.elastic_heights();
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const Vec3& v = sheet.mesh().vertices[static_cast<std::size_t>(j * n + i)];
        const double dist_m = std::hypot(v.x(), v.y());
        if (dist_m <= reach_m) {
          std::fprintf(out, "grid,%.6g,%.6g,%.9g\n", f, dist_m * 1e3,
                       -z[static_cast<std::size_t>(j * n + i)] * 1e3);
        }
      }
    }
  }
  out_file.commit();
  if (!args.out_path.empty()) {
    std::printf("written      %s\n", args.out_path.c_str());
  }
}

}  // namespace

void add_sheet_profile_command(CLI::App& app) {
  auto args = std::make_shared<SheetProfileArgs>();
  CLI::App* cmd = app.add_subcommand(
      "sheet-profile",
      "The virtual sheet's Gaussian deformation model (seed 000 Fig. 3) sampled as CSV: the "
      "profile against distance from a contact, and the scene's grid nodes under one push");
  cmd->add_option("scene", args->scene, "A scene with a virtual sheet (e.g. scenes/teleop.json)")
      ->required();
  cmd->add_option("--force", args->forces_n, "Pushes to sample, newtons (default 1,2,4)")
      ->delimiter(',');
  cmd->add_option("--out", args->out_path, "Write the CSV to FILE (default: standard output)");
  cmd->callback([args] { run_sheet_profile(*args); });
}

}  // namespace hapsim::app
