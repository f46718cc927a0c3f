#include "hapsim/device/glove_sensor_layout.h"

namespace hapsim {

const std::array<GloveSensorSpec, kGloveSensors>& glove_sensor_layout() {
  // Cross-talk modelled where a real bend sensor crosses two joints: the thumb's rotation sensor
  // lies over its MCP; a spread sensor between two fingers bends when the outer finger's MCP
  // flexes; the ring-little sensor sees the angle between them, so the ring's abduction too.
  static const std::array<GloveSensorSpec, kGloveSensors> layout{{
      {"thumb rotation (across the palm)", 0, 1},
      {"thumb MCP flexion", 1, -1},
      {"thumb IP flexion", 2, -1},
      {"index MCP flexion", 4, -1},
      {"index PIP flexion", 5, -1},
      {"middle MCP flexion", 7, -1},
      {"middle PIP flexion", 8, -1},
      {"ring MCP flexion", 10, -1},
      {"ring PIP flexion", 11, -1},
      {"little MCP flexion", 13, -1},
      {"little PIP flexion", 14, -1},
      {"index-middle spread", 3, 4},
      {"middle-ring spread", 9, 10},
      {"ring-little spread", 12, 9},
  }};
  return layout;
}

std::string glove_joint_name(int joint) {
  std::string name = "j";
  name += std::to_string(joint);
  return name;
}

std::string glove_sensor_name(int sensor) {
  std::string name = "s";
  name += std::to_string(sensor);
  return name;
}

std::string glove_joint_label(int joint) {
  static constexpr std::array<std::string_view, kHandFingers> fingers{"thumb", "index", "middle",
                                                                      "ring", "little"};
  static constexpr std::array<std::string_view, kGloveAnglesPerFinger> angles{"abduction", "MCP",
                                                                              "PIP"};
  std::string label = glove_joint_name(joint);
  if (joint >= 0 && joint < kGloveJoints) {
    label += " (" + std::string(fingers[static_cast<std::size_t>(joint / 3)]) + " " +
             std::string(joint == 2 ? std::string_view("IP")
                                    : angles[static_cast<std::size_t>(joint % 3)]) +
             ")";
  }
  return label;
}

std::string glove_sensor_label(int sensor) {
  std::string label = glove_sensor_name(sensor);
  if (sensor >= 0 && sensor < kGloveSensors) {
    label += " (" + std::string(glove_sensor_layout()[static_cast<std::size_t>(sensor)].name) + ")";
  }
  return label;
}

}  // namespace hapsim
