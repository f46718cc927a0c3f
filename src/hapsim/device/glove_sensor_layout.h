// The raw sensors of a DataGlove-class flexion glove as hapsim calibrates them
// (docs/glove-calibration.md): which hand-model joint angle each sensor reads, and which second
// joint it also sees (cross-talk). Layout "hapsim-glove-14/1": MCP and PIP flexion of every
// finger (the thumb's MCP and IP), the thumb's rotation across the palm, and three spread sensors
// between adjacent fingers. The middle finger's abduction (j6) has no sensor: the spread sensors
// measure from it, as anatomy measures abduction from the middle finger's axis, so it is 0.
#pragma once

#include "hapsim/kinematics/hand_model.h"

#include <array>
#include <string>
#include <string_view>

namespace hapsim {

inline constexpr std::string_view kGloveLayoutName = "hapsim-glove-14/1";
inline constexpr int kGloveSensors = 14;
/// The hand model's glove angles j0..j14: finger f's abduction, MCP, PIP at 3f, 3f+1, 3f+2.
inline constexpr int kGloveJoints = kHandFingers * kGloveAnglesPerFinger;
/// The one joint no sensor of the layout reads (the middle finger's abduction): held at 0.
inline constexpr int kGloveUnmeasuredJoint = 6;

struct GloveSensorSpec {
  /// What the sensor is, e.g. "index MCP flexion".
  std::string_view name;
  /// The joint angle it reads (j0..j14) and the second one it also sees, or -1.
  int joint = 0;
  int coupled_joint = -1;
};

/// The layout, sensor s at index s. Every joint but kGloveUnmeasuredJoint is some sensor's
/// `joint`, exactly once.
[[nodiscard]] const std::array<GloveSensorSpec, kGloveSensors>& glove_sensor_layout();

/// "j4" and "s3": the column names (written by appending: GCC 12 warns falsely on "j" + string).
[[nodiscard]] std::string glove_joint_name(int joint);
[[nodiscard]] std::string glove_sensor_name(int sensor);
/// "j4 (index MCP)" for messages.
[[nodiscard]] std::string glove_joint_label(int joint);
/// "s3 (index MCP flexion)" for messages.
[[nodiscard]] std::string glove_sensor_label(int sensor);

}  // namespace hapsim
