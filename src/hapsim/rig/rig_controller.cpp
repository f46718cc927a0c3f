#include "hapsim/rig/rig_controller.h"

#include "hapsim/core/error.h"
#include "hapsim/world/content_fingerprint.h"
#include "hapsim/world/world.h"
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_state.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

namespace hapsim {

namespace {

void check_rig(const TeleopRigDescription& d) {
  if (!d.slave) {
    throw Error("teleop", "no slave arm");
  }
  if (!d.slave_start_rad.empty() &&
      d.slave_start_rad.size() != static_cast<std::size_t>(d.slave->dof())) {
    throw Error("teleop", "slave start has " + std::to_string(d.slave_start_rad.size()) +
                              " joint values; the slave has " + std::to_string(d.slave->dof()));
  }
  if (!d.ball_start_world.allFinite() || !std::isfinite(d.force_scale) || d.force_scale < 0.0) {
    throw Error("teleop", "ball start must be finite and the force scale >= 0");
  }
  const ParallelGripperParams& g = d.gripper;
  if (!(g.pad_half_m.minCoeff() > 0.0) || !g.pad_half_m.allFinite() ||
      !std::isfinite(g.pad_depth_m) || !(g.pad_contact.stiffness_n_per_m > 0.0) ||
      !(g.max_force_n > 0.0) || !std::isfinite(g.max_force_n) || !(g.safety_factor >= 1.0)) {
    throw Error("teleop",
                "gripper pads need finite sizes > 0, a stiffness and force limit > 0 "
                "and a safety factor >= 1");
  }
}

// The rig's bodies are where rig_world() or add_rig() put them, of the kinds the rig expects; its
// carried tool is device 0's probe.
void check_rig_bodies(const WorldDescription& w, const TeleopRigDescription& d) {
  constexpr std::size_t kNone = TeleopRigDescription::kNoBody;
  const auto is = [&](std::size_t b, BodyKind kind) {
    return b < w.bodies.size() && w.bodies[b].kind == kind;
  };
  const bool ball_ok = d.ball_body == kNone || (is(d.ball_body, BodyKind::kDynamic) &&
                                                w.bodies[d.ball_body].segments.front().sphere);
  const bool sheet_ok = d.sheet_body == kNone ||
                        (is(d.sheet_body, BodyKind::kDeformable) &&
                         w.bodies[d.sheet_body].deformation == BodyDeformation::kGaussianSheet);
  if (!ball_ok || !sheet_ok || !is(d.pad_body[0], BodyKind::kKinematic) ||
      !is(d.pad_body[1], BodyKind::kKinematic) ||
      (d.floor_body != kNone && !is(d.floor_body, BodyKind::kStatic)) ||
      std::any_of(d.slave_bodies.begin(), d.slave_bodies.end(),
                  [&](const TeleopRigDescription::SlaveBody& s) {
                    return !is(s.body, BodyKind::kKinematic) ||
                           !(s.frame == kToolFrame || (s.frame >= -1 && s.frame < d.slave->dof()));
                  })) {
    throw Error("teleop",
                "the rig's ball, sheet, pads, floor and slave links must be bodies of the world "
                "(build the world with rig_world() or add_rig())");
  }
  if (d.carried_tool != TeleopRigDescription::kNoTool &&
      (d.carried_tool >= w.tools.size() || w.tools[d.carried_tool].device != 0 ||
       w.tools[d.carried_tool].finger >= 0 || w.has_hand)) {
    throw Error("teleop",
                "the tool the slave carries must be one of the world's tools, on "
                "device 0, with no finger, in a world without a glove hand");
  }
}

std::vector<double> start_joints(const TeleopRigDescription& d) {
  return d.slave_start_rad.empty() ? std::vector<double>(static_cast<std::size_t>(d.slave->dof()))
                                   : d.slave_start_rad;
}

// The rig's sheet among the world's sheets, in flat segment order (StepResult::sheet_depth_m);
// 0 without one.
std::size_t sheet_index_of(const WorldModel& model, std::size_t sheet_body) {
  if (sheet_body == TeleopRigDescription::kNoBody) {
    return 0;
  }
  const std::size_t flat = model.flat_segment(BodyIndex{sheet_body}, LocalSegment{0}).index();
  const std::vector<SegmentModel>& segs = model.segments();
  return static_cast<std::size_t>(std::count_if(segs.begin(),
                                                segs.begin() + static_cast<std::ptrdiff_t>(flat),
                                                [](const SegmentModel& s) { return s.sheet; }));
}

// The master's description checked before its model is built from it.
const TeleopRigDescription& checked(const TeleopRigDescription& d) {
  check_rig(d);
  return d;
}

}  // namespace

RigController::RigController(TeleopRigDescription description)
    : description_(std::move(description)), master_(checked(description_).master) {}

void RigController::check(const WorldDescription& world) const {
  check_rig_bodies(world, description_);
}

void RigController::fingerprint(ContentFingerprint& h) const {
  // What makes two rigs step differently: the slave, its start and limits, the mapping, the ball,
  // the sheet.
  h.number(description_.slave ? description_.slave->dof() : -1);
  for (const double q : description_.slave_start_rad) {
    h.number(q);
  }
  h.number(description_.mapping.scale);
  h.bytes(description_.mapping.X_slave_master.matrix().data(), sizeof(double) * 16);
  for (const double x :
       {description_.ball.mass_kg, description_.ball.radius_m, description_.gripper.max_force_n,
        description_.follower.gripper_max_width_m, description_.follower.gripper_speed_m_per_s,
        description_.follower.max_joint_acceleration_per_s2, description_.sheet.side_m,
        description_.force_scale}) {
    h.number(x);
  }
  h.bytes(description_.ball_start_world.data(), sizeof(double) * 3);
  h.number(description_.sheet.nodes_per_side);
  h.bytes(description_.environment.X_world_sheet.matrix().data(), sizeof(double) * 16);
}

std::unique_ptr<ControllerState> RigController::make_state(const WorldModel& model) const {
  return std::make_unique<RigState>(*this, model);
}

double RigController::slave_width_for(double master_opening_m) const noexcept {
  const MasterArmGeometry& g = master_.geometry();
  const double widest = 2.0 * g.finger_m * std::sin(g.finger_open_limit_rad);
  const double u = std::clamp((master_opening_m - g.finger_gap_m) / widest, 0.0, 1.0);
  return u * description_.follower.gripper_max_width_m;
}

RigState::RigState(const RigController& rig_controller, const WorldModel& model)
    : controller(&rig_controller),
      description(&rig_controller.description()),
      slave_start_rad(start_joints(*description)),
      slave(std::make_unique<SlaveFollower>(*description->slave, slave_start_rad,
                                            description->follower)),
      frames(static_cast<std::size_t>(description->slave->dof())),
      slave_body_previous(description->slave_bodies.size()),
      sheet_index(sheet_index_of(model, description->sheet_body)) {
  find_slave_collision_pairs(model, *this);
}

RigState::~RigState() = default;

// haptic path
void RigState::reset() noexcept {
  slave->reset(slave_start_rad);
  input_usable = false;
  has_pad_previous = false;
  held = false;
  grip_lost_since_s = -1.0;
  result = TeleopStepResult{};
}

const RigController* rig_controller(const WorldDescription& world) noexcept {
  return dynamic_cast<const RigController*>(world.controller.get());
}

const TeleopRigDescription* rig_description(const WorldDescription& world) noexcept {
  const RigController* rig = rig_controller(world);
  return rig != nullptr ? &rig->description() : nullptr;
}

const RigState* rig_state(const World& world) noexcept {
  return dynamic_cast<const RigState*>(world.controller());
}

const TeleopStepResult* rig_result(const StepResult& result) noexcept {
  const auto* rig = dynamic_cast<const RigState*>(result.controller);
  return rig != nullptr ? &rig->result : nullptr;
}

}  // namespace hapsim
