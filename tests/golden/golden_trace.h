// A golden trace: what a shipped scene's run did, cycle by cycle, in a form that does not depend on
// how the simulation is built (recorded before the one-world refactor, compared after it).
//
// Per cycle, named values (the command the device got: tip force, finger forces, joint torques;
// for teleoperation also the ball and the grasp) and the contacts as (tool, body, segment, force).
// Stored as gzip'd text under tests/golden/: one line per cycle in which something happened
// (cycles with all values zero and no contact are left out), doubles printed with 17 digits.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace hapsim::test {

struct GoldenContact {
  std::int32_t tool = -1;
  std::int32_t body = -1;
  std::int32_t segment = -1;
  double force_n = 0.0;
};

struct GoldenCycle {
  std::uint64_t index = 0;
  std::vector<double> values;  // one per GoldenTrace::columns
  std::vector<GoldenContact> contacts;
};

struct GoldenTrace {
  std::string scene;
  std::vector<std::string> columns;
  std::uint64_t cycle_count = 0;
  std::vector<GoldenCycle> cycles;  // only cycles with a non-zero value or a contact
};

/// Adds a cycle unless it is all zeros with no contact.
void append_cycle(GoldenTrace& trace, GoldenCycle cycle);

void write_golden(const std::filesystem::path& file, const GoldenTrace& trace);
/// Throws std::runtime_error naming the file and line on a malformed trace.
[[nodiscard]] GoldenTrace read_golden(const std::filesystem::path& file);

/// Empty when the traces agree: the same columns and cycle count, the same contacts (tool, body,
/// segment) in the same cycles and every value and contact force within `tolerance`. Otherwise
/// the first difference, in words, plus how many cycles differ.
[[nodiscard]] std::string compare_golden(const GoldenTrace& expected, const GoldenTrace& actual,
                                         double tolerance);

}  // namespace hapsim::test
