// The `hapsim` command: one binary, one subcommand per job (info, query, bench, ...).
// Every user-facing failure is one line on stderr and exit status 2.
#include "cli_main.h"
#include "commands.h"

#include "hapsim/version.h"

#include <spdlog/spdlog.h>

namespace hapsim::app {

int& exit_status() {
  static int status = 0;
  return status;
}

}  // namespace hapsim::app

int main(int argc, char** argv) {
  using namespace hapsim::app;
  CLI::App app{"hapsim - real-time haptic simulation"};
  app.set_version_flag("--version", "hapsim " HAPSIM_VERSION_STRING);  // project(VERSION)
  app.require_subcommand(1);
  spdlog::set_level(spdlog::level::warn);
  app.add_flag_callback(
      "-v,--verbose", [] { spdlog::set_level(spdlog::level::debug); }, "More log output");
  add_info_command(app);
  add_query_command(app);
  add_run_command(app);
  add_assess_command(app);
  add_view_command(app);
  add_kinematics_commands(app);
  add_serve_command(app);
  add_device_command(app);
  add_watch_command(app);
  add_control_command(app);
  add_simplify_command(app);
  add_polygonize_command(app);
  add_tetrahedralize_command(app);
  add_sheet_profile_command(app);
  add_calibrate_command(app);
  add_keys_command(app);
  add_doctor_command(app);
  add_bench_command(app);
  return run_cli_main(app, argc, argv, "hapsim");
}
