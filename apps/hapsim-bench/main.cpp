// `hapsim-bench`: the benchmarks (`hapsim bench SUBCOMMAND ...` runs `hapsim-bench SUBCOMMAND
// ...`). A program of its own so that `hapsim` links none of the reference libraries the
// collision benchmark compares against (CGAL, FCL, Embree); the same subcommands, options,
// tables, JSON and exit statuses as `hapsim bench` always had.
#include "bench_commands.h"
#include "cli_main.h"
#include "commands.h"

#include <spdlog/spdlog.h>

namespace hapsim::app {

int& exit_status() {
  static int status = 0;
  return status;
}

}  // namespace hapsim::app

int main(int argc, char** argv) {
  using namespace hapsim::app;
  CLI::App app{"Benchmarks (tables on stdout, JSON on request)", "hapsim bench"};
  app.set_version_flag("--version", "hapsim-bench 0.1.0");
  app.require_subcommand(1);
  spdlog::set_level(spdlog::level::warn);
  app.add_flag_callback(
      "-v,--verbose", [] { spdlog::set_level(spdlog::level::debug); }, "More log output");
  add_bench_subcommands(app);
  return run_cli_main(app, argc, argv, "hapsim bench");
}
