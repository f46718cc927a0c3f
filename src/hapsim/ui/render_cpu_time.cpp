#include "hapsim/ui/render_cpu_time.h"

#include <unistd.h>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace hapsim {
namespace {

// utime + stime of one /proc/self/task/TID/stat, when the thread's name starts with `prefix`.
double task_cpu_s(const std::filesystem::path& stat_path, const std::string& prefix) {
  std::ifstream in(stat_path);
  std::string line;
  if (!std::getline(in, line)) {
    return 0.0;
  }
  // "tid (comm) state ppid …": comm may hold spaces, so split at its closing parenthesis.
  const auto open = line.find('(');
  const auto close = line.rfind(')');
  if (open == std::string::npos || close == std::string::npos || close < open) {
    return 0.0;
  }
  if (line.compare(open + 1, prefix.size(), prefix) != 0) {
    return 0.0;
  }
  std::istringstream fields(line.substr(close + 2));
  std::string skip;
  for (int i = 3; i < 14; ++i) {  // fields 3 … 13, then utime (14) and stime (15)
    fields >> skip;
  }
  double utime = 0.0;
  double stime = 0.0;
  fields >> utime >> stime;
  const long ticks = sysconf(_SC_CLK_TCK);
  return ticks > 0 ? (utime + stime) / static_cast<double>(ticks) : 0.0;
}

}  // namespace

RenderCpuTime render_cpu_time_now() {
  RenderCpuTime t;
  timespec ts{};
  if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) == 0) {
    t.viewer_thread_s = static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
  }
  std::error_code ec;
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task", ec)) {
    t.rasteriser_s += task_cpu_s(task.path() / "stat", "llvmpipe");
  }
  return t;
}

}  // namespace hapsim
