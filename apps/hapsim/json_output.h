// `--json FILE` of the commands: opened before the run (a bad path fails at once, not after a long
// run), written once at the end, atomically (checked_output.h), with its failure said, and the
// "wrote" line printed only when it was written.
#pragma once

#include "checked_output.h"
#include "commands.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <memory>
#include <string>

namespace hapsim::app {

class JsonOutput {
 public:
  /// Opens `path` now unless it is empty. Throws CommandError naming --json when it cannot.
  explicit JsonOutput(std::string path) : path_(std::move(path)) {
    if (!path_.empty()) {
      file_ = open_output("--json", path_);
    }
  }

  /// Whether --json was given.
  explicit operator bool() const { return !path_.empty(); }

  /// Writes `j` (indented) and says so; throws CommandError when the write fails. Once only.
  void write(const nlohmann::json& j) {
    if (file_ == nullptr) {
      throw CommandError("--json " + path_ + ": written twice (or not given)");
    }
    const std::unique_ptr<AtomicFile> file = std::move(file_);
    commit_output(*file, "--json", j.dump(2) + '\n');
    std::printf("wrote        %s\n", path_.c_str());
  }

 private:
  std::string path_;
  std::unique_ptr<AtomicFile> file_;
};

}  // namespace hapsim::app
