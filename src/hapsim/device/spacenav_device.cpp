#include "hapsim/device/spacenav_device.h"

#include "hapsim/core/error.h"

#include <poll.h>
#include <spnav.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace hapsim {
namespace {

double shaped(int reading, const SpacenavOptions& o) {
  return dead_zoned(static_cast<double>(reading) / o.full_scale, o.dead_zone);
}

double normalised(int reading, const SpacenavOptions& o) {
  return std::clamp(static_cast<double>(reading) / o.full_scale, -1.0, 1.0);
}

}  // namespace

SpacenavDevice::SpacenavDevice(DeviceProfile profile, SpacenavOptions options)
    : options_(options), inner_(std::move(profile), [&] {
        DeviceInput in;
        in.p_world = options.start_p_world;
        return in;
      }()) {
  if (spnav_open() == -1) {
    throw Error("3D mouse",
                "none found: the spacenavd daemon does not answer (is it installed and running, "
                "and a SpaceMouse plugged in?)");
  }
  reader_ = std::thread([this] { reader_main(); });
}

SpacenavDevice::~SpacenavDevice() {
  stop_.store(true);
  if (reader_.joinable()) {
    reader_.join();
  }
  spnav_close();
}

// Not the haptic path: its own thread, blocking on the daemon's socket with a timeout.
void SpacenavDevice::reader_main() {
  DeviceInput input;
  input.p_world = options_.start_p_world;
  int motion[6] = {0, 0, 0, 0, 0, 0};
  std::uint32_t buttons = 0;
  auto last = std::chrono::steady_clock::now();
  while (!stop_.load()) {
    pollfd fd{spnav_fd(), POLLIN, 0};
    const int ready = ::poll(&fd, 1, 10);
    if (ready < 0 || (fd.revents & (POLLHUP | POLLERR | POLLNVAL)) != 0) {
      inner_.set_connected(false);  // the daemon went away: the loop ramps the force down
      return;
    }
    spnav_event ev{};
    while (spnav_poll_event(&ev) != 0) {
      if (ev.type == SPNAV_EVENT_MOTION) {
        motion[0] = ev.motion.x;
        motion[1] = ev.motion.y;
        motion[2] = ev.motion.z;
        motion[3] = ev.motion.rx;
        motion[4] = ev.motion.ry;
        motion[5] = ev.motion.rz;
      } else if (ev.type == SPNAV_EVENT_BUTTON) {
        const std::uint32_t bit = 1U << static_cast<unsigned>(std::clamp(ev.button.bnum, 0, 31));
        buttons = ev.button.press != 0 ? (buttons | bit) : (buttons & ~bit);
      }
    }
    const auto now = std::chrono::steady_clock::now();
    const double dt = std::min(0.05, std::chrono::duration<double>(now - last).count());
    last = now;
    {
      const std::lock_guard<std::mutex> lock(axes_mutex_);
      axes_.translation = Vec3(normalised(motion[0], options_), normalised(motion[1], options_),
                               normalised(motion[2], options_));
      axes_.rotation = Vec3(normalised(motion[3], options_), normalised(motion[4], options_),
                            normalised(motion[5], options_));
    }
    if (drives_camera_.load()) {
      continue;  // the viewer turns the camera with it; the tool holds still
    }
    // spacenavd's frame: x right, y up, z towards the user; the world is Z-up, Y away from the
    // user in the default view.
    const Vec3 v(shaped(motion[0], options_), -shaped(motion[2], options_),
                 shaped(motion[1], options_));
    const Vec3 w(shaped(motion[3], options_), -shaped(motion[5], options_),
                 shaped(motion[4], options_));
    input.p_world += options_.full_speed_m_per_s * dt * v;
    const double angle = options_.full_turn_rad_per_s * dt * w.norm();
    if (angle > 0.0) {
      input.q_world = (Quat(Eigen::AngleAxisd(angle, w.normalized())) * input.q_world).normalized();
    }
    input.buttons = buttons;
    inner_.set_input(input);
  }
}

SpaceMouseAxes SpacenavDevice::axes() const {
  const std::lock_guard<std::mutex> lock(axes_mutex_);
  return axes_;
}

}  // namespace hapsim
