// `hapsim bench ...`: runs `hapsim-bench ...` from this binary's folder with the same arguments
// (exec: same process, its output and exit status). The benchmarks are a program of their own
// (apps/hapsim-bench/) because the collision benchmark links CGAL, FCL and Embree, reference
// libraries for tests and benchmarks that `hapsim` itself must not depend on.
#include "commands.h"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace hapsim::app {
namespace {

[[noreturn]] void exec_bench(const std::vector<std::string>& args) {
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  const std::filesystem::path bench =
      (ec ? std::filesystem::path(".") : self.parent_path()) / "hapsim-bench";
  if (::access(bench.c_str(), X_OK) != 0) {
    throw CommandError(
        "hapsim bench needs hapsim-bench, built with the benchmarks "
        "(cmake -DHAPSIM_BUILD_BENCH=ON, the default): no " +
        bench.string());
  }
  std::vector<std::string> words{bench.string()};
  // -v before `bench` (hapsim -v bench ...) carries over.
  if (spdlog::get_level() <= spdlog::level::debug) {
    words.emplace_back("-v");
  }
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  argv.reserve(words.size() + 1);
  for (std::string& w : words) {
    argv.push_back(w.data());
  }
  argv.push_back(nullptr);
  ::execv(bench.c_str(), argv.data());
  throw CommandError("hapsim bench: could not run " + bench.string() + ": " + std::strerror(errno));
}

}  // namespace

void add_bench_command(CLI::App& app) {
  CLI::App* bench = app.add_subcommand(
      "bench",
      "Benchmarks (tables on stdout, JSON on request): collision, step, passivity, snapshot, "
      "contact, fem, soak, network; run by hapsim-bench, built with the benchmarks (hapsim bench "
      "--help lists them)");
  // Everything after `bench`, --help included, goes to hapsim-bench as it was given.
  bench->prefix_command();
  bench->allow_extras();
  bench->set_help_flag();
  bench->callback([bench] { exec_bench(bench->remaining()); });
}

}  // namespace hapsim::app
