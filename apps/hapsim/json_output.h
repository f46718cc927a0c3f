// `--json FILE` of the commands: opened before the run (a bad path fails at once, not after a long
// run), written once at the end, atomically (checked_output.h), with its failure said, and the
// "wrote" line printed only when it was written.
#pragma once

#include "checked_output.h"
#include "commands.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <exception>
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
  /// Whether it is still to be written (given, and no write was tried).
  [[nodiscard]] bool pending() const { return file_ != nullptr; }

  /// For a run that failed before its summary: {"ok": false, "error": what}, so a script reading
  /// the JSON learns the failure rather than finding the file missing or empty. Says nothing
  /// (the failure's own line is the one line); a failed write here is not said either.
  void write_failure(const std::string& what) noexcept {
    if (file_ == nullptr) {
      return;
    }
    const std::unique_ptr<AtomicFile> file = std::move(file_);
    try {
      file->write(nlohmann::json{{"ok", false}, {"error", what}}.dump(2) + '\n');
      file->commit();
    } catch (...) {  // NOLINT(bugprone-empty-catch): the run's own failure is the one said
    }
  }

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

/// Runs `body`, which writes `json` at its end; when it throws first, `json` gets the failure
/// (JsonOutput::write_failure) and the exception goes on.
template <typename Body>
void with_failure_json(JsonOutput& json, Body&& body) {
  try {
    body();
  } catch (const std::exception& e) {
    json.write_failure(e.what());
    throw;
  }
}

}  // namespace hapsim::app
