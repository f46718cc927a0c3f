// A timed sequence of device inputs (pose, finger and joint angles, buttons): what a simulated
// device plays back, loaded from a CSV file (docs/trajectory-format.md) or built in code.
#pragma once

#include "hapsim/core/device_io.h"

#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace hapsim {

/// How far from 1 a quaternion's norm may be before it is taken for a mistake (e.g. a column
/// order mix-up) rather than rounding in a hand-written file.
inline constexpr double kQuatNormTolerance = 1e-3;
/// Raw glove sensor columns s0..s31 (docs/glove-calibration.md): counts, not angles.
inline constexpr int kMaxRawSensors = 32;

struct Trajectory {
  /// Samples with strictly increasing time_s, unit quaternions, finite values; every sample has
  /// the same finger_count / joint_count as the trajectory.
  std::vector<DeviceInput> samples;
  int finger_count = 0;
  int joint_count = 0;
  /// Whether the source had a `buttons` column (otherwise buttons are 0).
  bool has_buttons = false;
  /// Raw glove sensor counts (columns s0..sN): sensor_count per sample, sample-major. A glove
  /// calibration turns them into joint angles when the trajectory is loaded
  /// (device/glove_calibration.h); sample_at() does not interpolate them.
  int sensor_count = 0;
  std::vector<double> sensor_counts;

  /// Sample i's raw sensor counts (empty when the trajectory has none).
  [[nodiscard]] std::span<const double> sensors(std::size_t i) const {
    return std::span<const double>(sensor_counts)
        .subspan(i * static_cast<std::size_t>(sensor_count),
                 static_cast<std::size_t>(sensor_count));
  }

  [[nodiscard]] bool empty() const { return samples.empty(); }
  [[nodiscard]] std::size_t size() const { return samples.size(); }
  [[nodiscard]] double start_time_s() const { return samples.front().time_s; }
  [[nodiscard]] double end_time_s() const { return samples.back().time_s; }

  /// haptic path (no allocation; O(log n)). The input at `time_s`: positions and angles linear
  /// between samples, orientation by slerp (shorter arc), buttons held from the earlier sample;
  /// exactly the sample at a sample time; the first sample before the start and the last after
  /// the end. The result's time_s is `time_s`. Precondition: !empty().
  [[nodiscard]] DeviceInput sample_at(double time_s) const noexcept;
};

/// Checks the invariants above (times, finiteness, |q| within kQuatNormTolerance of 1, counts)
/// and normalises the quaternions exactly. Throws hapsim::Error naming `where` and
/// the sample index. For trajectories built in code (waypoints).
[[nodiscard]] Trajectory make_trajectory(std::vector<DeviceInput> samples, int finger_count,
                                         int joint_count, std::string_view where);

/// Parses the CSV text (docs/trajectory-format.md); `source_name` (a file name) prefixes every
/// error as "source:line:column". Throws hapsim::Error; never crashes on bad input.
[[nodiscard]] Trajectory parse_trajectory_csv(std::string_view text, std::string_view source_name);

/// Reads and parses a trajectory CSV file.
[[nodiscard]] Trajectory load_trajectory_csv(const std::filesystem::path& path);

/// CSV text in SI units that parses back to bit-identical samples (shortest round-trip digits).
[[nodiscard]] std::string format_trajectory_csv(const Trajectory& trajectory);

void save_trajectory_csv(const Trajectory& trajectory, const std::filesystem::path& path);

}  // namespace hapsim
