// The `hapsim` command: one binary, one subcommand per job (info, query, bench, ...).
// Every user-facing failure is one line on stderr and exit status 2.
#include "commands.h"

#include "hapsim/core/error.h"

#include <spdlog/spdlog.h>

#include <exception>
#include <filesystem>
#include <iostream>

namespace hapsim::app {

int& exit_status() {
  static int status = 0;
  return status;
}

}  // namespace hapsim::app

int main(int argc, char** argv) {
  using namespace hapsim::app;
  CLI::App app{"hapsim - real-time haptic simulation"};
  app.set_version_flag("--version", "hapsim 0.1.0");
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
#ifdef HAPSIM_WITH_BENCH
  add_bench_command(app);
#endif
  try {
    app.parse(argc, argv);  // subcommand callbacks run inside parse()
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "hapsim: " << e.what() << " (see hapsim --help)\n";
    return 2;
  } catch (const CommandError& e) {
    std::cerr << "hapsim: " << e.what() << "\n";
    return 2;
  } catch (const hapsim::Error& e) {
    std::cerr << "hapsim: " << e.what() << "\n";
    return 2;
  } catch (const std::filesystem::filesystem_error& e) {
    // A path the user gave that the file system refuses (a symlink loop, an unreadable folder,
    // a name too long) is bad input like any other: name the path and the reason.
    const std::string path = e.path1().empty() ? std::string("a path") : e.path1().string();
    std::cerr << "hapsim: " << path << ": " << e.code().message() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "hapsim: internal error: " << e.what() << "\n";
    return 1;
  }
  return exit_status();
}
