// Subcommands of the `hapsim` app, one file each. Each `add_*` registers its CLI11 subcommand;
// the callback runs it and throws CommandError (exit 2, one line) on bad input.
#pragma once

#include <CLI/CLI.hpp>

#include <stdexcept>
#include <string>

namespace hapsim::app {

/// A user-facing failure: printed as one line "hapsim: <message>", exit status 2.
class CommandError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A CLI11 check for a length of time in seconds: a finite number > 0 ("nan" passes CLI11's own
/// PositiveNumber, and would read as "not given").
inline CLI::Validator positive_seconds() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(text, v) || !(v > 0.0) || !(v < 1e300)) {
          return "expected a finite number of seconds > 0, got '" + text + "'";
        }
        return {};
      },
      "SECONDS>0");
}

/// Exit status a subcommand's callback sets for main() to return (0 unless it says otherwise).
int& exit_status();

void add_info_command(CLI::App& app);
void add_query_command(CLI::App& app);
/// `hapsim bench ...` (bench_command.cpp): runs `hapsim-bench ...`, the benchmarks' own program
/// beside this one (apps/hapsim-bench/), so `hapsim` links none of the benchmark oracles.
void add_bench_command(CLI::App& app);
void add_run_command(CLI::App& app);
void add_assess_command(CLI::App& app);
void add_view_command(CLI::App& app);
void add_kinematics_commands(CLI::App& app);
void add_serve_command(CLI::App& app);
void add_device_command(CLI::App& app);
void add_watch_command(CLI::App& app);
void add_control_command(CLI::App& app);
void add_simplify_command(CLI::App& app);
void add_polygonize_command(CLI::App& app);
void add_tetrahedralize_command(CLI::App& app);
void add_sheet_profile_command(CLI::App& app);
void add_calibrate_command(CLI::App& app);
/// `hapsim keys` (keys_command.cpp): a secure session's keys.
void add_keys_command(CLI::App& app);
/// `hapsim doctor` (doctor_command.cpp): what the machine gives hapsim, each check with its fix.
void add_doctor_command(CLI::App& app);

}  // namespace hapsim::app
