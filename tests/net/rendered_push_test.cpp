// Which push each tool's device rendered, read back from the device host's command
// (net/model_publisher.h): a finger's actuator force for a finger tool, the tip force for the one
// tool on no finger, and "not known" (NaN) wherever the command cannot say.
#include "hapsim/net/model_publisher.h"

#include <array>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace hapsim::net {
namespace {

TEST(RenderedPushPerTool, FingerToolsReadTheirFingerAndOneTipToolTheTipForce) {
  DeviceCommand rendered;
  rendered.finger_count = 3;
  rendered.finger_force_n = {1.0, 2.0, 3.0, 9.0, 9.0};  // 3 and 4 beyond finger_count
  rendered.force_world_n = Vec3(0.0, 3.0, 4.0);
  const std::array<int, 5> fingers{2, 0, -1, 3, 1};
  std::array<double, 5> push{};
  rendered_push_per_tool(rendered, fingers, push);
  EXPECT_EQ(push[0], 3.0);
  EXPECT_EQ(push[1], 1.0);
  EXPECT_EQ(push[2], 5.0);           // |tip force|: the only tool on no finger
  EXPECT_TRUE(std::isnan(push[3]));  // the command carries no fourth finger
  EXPECT_EQ(push[4], 2.0);
}

TEST(RenderedPushPerTool, WhatCannotBeToldIsNotKnown) {
  DeviceCommand rendered;
  rendered.force_world_n = Vec3(0.0, 0.0, 2.0);
  rendered.finger_count = 2;
  rendered.finger_force_n[0] = std::numeric_limits<double>::quiet_NaN();
  rendered.finger_force_n[1] = -1.0;
  // Two tip tools share one tip force: neither can be told apart.
  const std::array<int, 4> fingers{-1, -1, 0, 1};
  std::array<double, 4> push{};
  rendered_push_per_tool(rendered, fingers, push);
  for (const double p : push) {
    EXPECT_TRUE(std::isnan(p));
  }
  rendered.force_world_n.x() = std::numeric_limits<double>::infinity();
  const std::array<int, 1> one_tip{-1};
  std::array<double, 1> tip{};
  rendered_push_per_tool(rendered, one_tip, tip);
  EXPECT_TRUE(std::isnan(tip[0]));
}

}  // namespace
}  // namespace hapsim::net
