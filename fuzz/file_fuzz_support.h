// What the file fuzz targets (scene, scene_step, mesh, trajectory, number_csv, recording, urdf)
// share: the input as text, a scratch file for the readers that take a path, and the rule they
// all check: a reader of a user's file returns or throws hapsim::Error; any other exception
// escaping (it would end as "internal error", exit 1) is a finding, as is a crash or a hang.
#pragma once

#include "fuzz_support.h"
#include "hapsim/core/error.h"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cstdint>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

namespace hapsim::fuzz {

// Mesh warnings and the like would print for most inputs and slow the fuzzer to a crawl.
inline const bool kQuietLog = [] {
  spdlog::set_level(spdlog::level::off);
  return true;
}();

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

/// A per-process scratch file named `name` (its extension chooses a mesh format), holding `bytes`.
inline std::filesystem::path scratch_file(const std::string& name, std::string_view bytes) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("hapsim_fuzz_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::filesystem::path path = dir / name;
  // A new file each time, not the old one truncated: on ext4, truncating a file that holds data
  // makes its close wait for the disk (auto_da_alloc), which was 3/4 of a recording's time.
  std::error_code ec;
  std::filesystem::remove(path, ec);
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return path;
}

/// Runs `read`; a hapsim::Error is the expected refusal, anything else escaping is a finding.
template <class Read>
void expect_value_or_error(Read&& read) {
  try {
    read();
  } catch (const hapsim::Error&) {
    // the reader said what was wrong and where
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz check failed: an exception other than hapsim::Error escaped: %s\n",
                 e.what());
    std::abort();
  }
}

}  // namespace hapsim::fuzz
