// `--json FILE` of the commands: opened before the run (a bad path fails at once, not after a long
// run), written once at the end with its failure said, and the "wrote" line printed.
#pragma once

#include "commands.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>
#include <memory>
#include <string>

namespace hapsim::app {

class JsonOutput {
 public:
  /// Opens `path` now unless it is empty. Throws CommandError naming --json when it cannot.
  explicit JsonOutput(std::string path) : path_(std::move(path)) {
    if (!path_.empty()) {
      out_ = std::make_unique<std::ofstream>(path_);
      if (!*out_) {
        throw CommandError("--json " + path_ + ": cannot open for writing");
      }
    }
  }

  /// Whether --json was given.
  explicit operator bool() const { return out_ != nullptr; }

  /// Writes `j` (indented) and says so; throws CommandError when the write fails.
  void write(const nlohmann::json& j) {
    *out_ << j.dump(2) << '\n';
    out_->flush();
    if (!*out_) {
      throw CommandError("--json " + path_ + ": write failed");
    }
    std::printf("wrote        %s\n", path_.c_str());
  }

 private:
  std::string path_;
  std::unique_ptr<std::ofstream> out_;
};

}  // namespace hapsim::app
