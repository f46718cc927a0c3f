// What `hapsim` and `hapsim-bench` do with a parsed command line: run it, and turn every
// user-facing failure into one line on stderr and exit status 2.
#pragma once

#include "commands.h"

#include "hapsim/core/error.h"

#include <CLI/CLI.hpp>

#include <exception>
#include <filesystem>
#include <iostream>
#include <string>

namespace hapsim::app {

/// Parses and runs `app` (subcommand callbacks run inside the parse); `help` names the command
/// whose --help a bad command line points to. Returns the process's exit status.
inline int run_cli_main(CLI::App& app, int argc, char** argv, const std::string& help) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "hapsim: " << e.what() << " (see " << help << " --help)\n";
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

}  // namespace hapsim::app
