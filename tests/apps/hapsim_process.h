// Running the real `hapsim` binary from tests: exit status and output, scratch files, CSV output.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace hapsim::test {

struct RunResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

/// `hapsim ARGS` run through `prefix` (e.g. "env -u NAME"), stdout and stderr together.
inline RunResult run_hapsim_env(const std::string& prefix, const std::string& args) {
  const std::string cmd = prefix + " " + std::string(HAPSIM_BIN_PATH) + " " + args + " 2>&1";
  RunResult result;
  std::FILE* pipe = popen(cmd.c_str(), "r");
  if (pipe == nullptr) {
    return result;
  }
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), static_cast<int>(buffer.size()), pipe) != nullptr) {
    result.output += buffer.data();
  }
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

inline RunResult run_hapsim(const std::string& args) {
  return run_hapsim_env("", args);
}

/// Forks and runs `words` (words[0] the program), stdout and stderr to `log`; the child's pid
/// (the caller waits for it).
inline pid_t spawn_logged(std::vector<std::string> words, const std::filesystem::path& log) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    std::vector<char*> argv;
    for (std::string& w : words) {
      argv.push_back(w.data());
    }
    argv.push_back(nullptr);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  return pid;
}

/// `hapsim ARGS` running in the background (its own process), its output going to a file: for the
/// multi-process tests, which start, kill and restart hosts.
class BackgroundHapsim {
 public:
  /// Starts `hapsim` with `args` (split on spaces; no quoting), output to `log`.
  BackgroundHapsim(const std::string& args, std::filesystem::path log) : log_(std::move(log)) {
    std::vector<std::string> words{HAPSIM_BIN_PATH};
    std::istringstream in(args);
    for (std::string w; in >> w;) {
      words.push_back(w);
    }
    pid_ = spawn_logged(std::move(words), log_);
  }
  BackgroundHapsim(const BackgroundHapsim&) = delete;
  BackgroundHapsim& operator=(const BackgroundHapsim&) = delete;
  ~BackgroundHapsim() {
    if (pid_ > 0 && exit_code_ == kRunning) {
      ::kill(pid_, SIGKILL);
      (void)wait();
    }
  }

  void signal(int sig) const { ::kill(pid_, sig); }
  /// Waits for the process to end; its exit code (-1 when killed by a signal).
  int wait() {
    if (exit_code_ == kRunning) {
      int status = 0;
      ::waitpid(pid_, &status, 0);
      exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }
    return exit_code_;
  }
  [[nodiscard]] std::string output() const {
    std::ifstream in(log_);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  /// True once the output holds `text`; false after `timeout`.
  bool wait_for(const std::string& text, std::chrono::milliseconds timeout) const {
    const auto give_up = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < give_up) {
      if (output().find(text) != std::string::npos) {
        return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return false;
  }

 private:
  static constexpr int kRunning = -2;
  std::filesystem::path log_;
  pid_t pid_ = -1;
  int exit_code_ = kRunning;
};

/// A path in this test process's own scratch folder (tests run in parallel under ctest).
inline std::filesystem::path temp_path(const std::string& name) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("hapsim_app_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir / name;
}

inline std::filesystem::path write_file(const std::string& name, const std::string& content) {
  const auto path = temp_path(name);
  std::ofstream(path) << content;
  return path;
}

/// Rows of numbers of a CSV with one header line.
inline std::vector<std::vector<double>> read_csv_numbers(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);  // header
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::stringstream ss(line);
    std::string field;
    while (std::getline(ss, field, ',')) {
      row.push_back(std::stod(field));
    }
    rows.push_back(row);
  }
  return rows;
}

}  // namespace hapsim::test
