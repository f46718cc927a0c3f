// A tool whose proxy starts inside a proxy body is one event, said once ("started inside"), not a
// pop-through per step; a proxy pushed into a body from outside still is one (once per entry).
#include "runtime/two_body_world.h"

#include "hapsim/core/device_profile.h"
#include "hapsim/device/simulated_device.h"
#include "hapsim/runtime/session.h"
#include "hapsim/world/world.h"

#include <gtest/gtest.h>

namespace hapsim {
namespace {

SessionSummary hold_at(const Vec3& p_world, double duration_s) {
  World world(test::two_body_world());
  SimulatedDevice device(
      device_profile("omega3"),
      [p_world](double t) {
        DeviceInput in;
        in.time_s = t;
        in.p_world = p_world;
        return in;
      },
      duration_s);
  SessionOptions options;
  options.duration_s = duration_s;
  return run_session(world, device, options);
}

TEST(StartedInside, AToolPlacedInsideABodyIsOneEventNotAPopThroughPerStep) {
  // 20 mm into the bone block (top face at z = 0, at x = 0), held for 0.5 s.
  const SessionSummary s = hold_at(Vec3(0.0, 0.0, -0.02), 0.5);
  EXPECT_EQ(s.pop_throughs, 0u);
  EXPECT_EQ(s.started_inside, 1u);
  EXPECT_NE(s.started_inside_first.find("tool 'tip' in"), std::string::npos)
      << s.started_inside_first;
  const std::string said = format_session_summary(s);
  EXPECT_NE(said.find("started inside: 1 time(s)"), std::string::npos) << said;
}

TEST(StartedInside, AToolOutsideCountsNothing) {
  const SessionSummary s = hold_at(Vec3(0.0, 0.0, 0.05), 0.2);
  EXPECT_EQ(s.pop_throughs, 0u);
  EXPECT_EQ(s.started_inside, 0u);
}

}  // namespace
}  // namespace hapsim
