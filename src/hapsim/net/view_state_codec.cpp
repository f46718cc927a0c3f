#include "hapsim/net/view_state_codec.h"

#include "hapsim/rig/rig_controller.h"

#include <algorithm>
#include <cmath>

namespace hapsim::net {

namespace {

template <typename T>
void point_at(T& seq, std::vector<typename std::remove_pointer_t<decltype(seq._buffer)>>& v) {
  seq._buffer = v.data();
  seq._length = static_cast<uint32_t>(v.size());
  seq._maximum = static_cast<uint32_t>(v.size());
  seq._release = false;
}

void put3(double (&out)[3], const Vec3& v) {
  for (int i = 0; i < 3; ++i) {
    out[i] = v[i];
  }
}

Vec3 get3(const double (&in)[3]) {
  return {in[0], in[1], in[2]};
}

constexpr auto kFingers = static_cast<std::size_t>(kHandFingers);
constexpr auto kAngles = static_cast<std::size_t>(kGloveAnglesPerFinger);
static_assert(kFingers * kAngles == sizeof(hapsim_msg_ViewState::hand_angles_rad) / sizeof(double),
              "the ViewState carries every glove angle");

bool finite3(const double (&in)[3]) {
  return std::isfinite(in[0]) && std::isfinite(in[1]) && std::isfinite(in[2]);
}

void put_pose(double (&p_m)[3], double (&q_wxyz)[4], const Iso3& X) {
  put3(p_m, X.translation());
  const Quat q(X.linear());
  q_wxyz[0] = q.w();
  q_wxyz[1] = q.x();
  q_wxyz[2] = q.y();
  q_wxyz[3] = q.z();
}

void encode_rig(const TeleopSnapshot& s, hapsim_msg_RigView& v) {
  std::copy(s.master_joint_rad.begin(), s.master_joint_rad.end(), v.master_joint_rad);
  std::copy(s.master_finger_rad.begin(), s.master_finger_rad.end(), v.master_finger_rad);
  for (int j = 0; j < std::min(s.output.joint_count, 5); ++j) {
    v.master_torque_nm[j] = s.output.joint_torque_nm[static_cast<std::size_t>(j)];
  }
  const std::size_t dof = std::min<std::size_t>(s.slave_q.size(), std::size(v.slave_q));
  v.slave_dof = static_cast<std::uint16_t>(dof);
  std::copy_n(s.slave_q.begin(), dof, v.slave_q);
  put_pose(v.tool_p_m, v.tool_q_wxyz, s.X_world_tool);
  v.gripper_width_m = s.gripper_width_m;
  v.pad_force_n[0] = s.pad_force_n[0];
  v.pad_force_n[1] = s.pad_force_n[1];
  v.held = s.held;
  v.sheet_depth_m = s.sheet_depth_m;
}

bool rig_view_fits(const hapsim_msg_RigView& v, std::size_t slave_dof, std::string& why) {
  if (v.slave_dof != slave_dof) {
    why = "a slave with " + std::to_string(v.slave_dof) + " joints (the scene's has " +
          std::to_string(slave_dof) + ")";
    return false;
  }
  const auto finite = [](const auto& values) {
    return std::all_of(std::begin(values), std::end(values),
                       [](double a) { return std::isfinite(a); });
  };
  const Quat q(v.tool_q_wxyz[0], v.tool_q_wxyz[1], v.tool_q_wxyz[2], v.tool_q_wxyz[3]);
  if (!finite(v.master_joint_rad) || !finite(v.master_finger_rad) || !finite(v.master_torque_nm) ||
      !finite(v.slave_q) || !finite3(v.tool_p_m) || !q.coeffs().allFinite() ||
      std::abs(q.norm() - 1.0) > 1e-3 || !std::isfinite(v.gripper_width_m) ||
      !finite(v.pad_force_n) || !std::isfinite(v.sheet_depth_m)) {
    why = "the rig's part has a non-finite number or its tool no rigid motion (|q| = " +
          std::to_string(q.norm()) + ")";
    return false;
  }
  return true;
}

// `master`: the viewer's own master arm, for the hand the joints put (not sent: it follows).
void decode_rig(const hapsim_msg_RigView& v, const MasterArm* master, TeleopSnapshot& s) {
  std::copy(std::begin(v.master_joint_rad), std::end(v.master_joint_rad),
            s.master_joint_rad.begin());
  std::copy(std::begin(v.master_finger_rad), std::end(v.master_finger_rad),
            s.master_finger_rad.begin());
  if (master != nullptr) {
    s.X_master_hand = master->hand_pose(s.master_joint_rad);
  }
  s.output = DeviceCommand{};
  s.output.joint_count = 5;
  std::copy(std::begin(v.master_torque_nm), std::end(v.master_torque_nm),
            s.output.joint_torque_nm.begin());
  std::copy_n(v.slave_q, std::min<std::size_t>(v.slave_dof, s.slave_q.size()), s.slave_q.begin());
  s.X_world_tool = Iso3::Identity();
  s.X_world_tool.linear() =
      Quat(v.tool_q_wxyz[0], v.tool_q_wxyz[1], v.tool_q_wxyz[2], v.tool_q_wxyz[3])
          .normalized()
          .toRotationMatrix();
  s.X_world_tool.translation() = get3(v.tool_p_m);
  s.gripper_width_m = v.gripper_width_m;
  s.pad_force_n = {v.pad_force_n[0], v.pad_force_n[1]};
  s.grasp_force_n = 0.5 * (v.pad_force_n[0] + v.pad_force_n[1]);
  s.held = v.held;
  s.sheet_depth_m = v.sheet_depth_m;
}

}  // namespace

ViewStateEncoder::ViewStateEncoder(const World& world)
    : rest_body_(make_world_snapshot(world).positions_body) {}

const hapsim_msg_ViewState& ViewStateEncoder::encode(const WorldSnapshot& s,
                                                     std::uint64_t scene_hash,
                                                     std::uint64_t serve_id, bool host_driving,
                                                     bool paused) {
  hapsim_msg_ViewState& m = message_;
  m = hapsim_msg_ViewState{};
  m.scene_hash = scene_hash;
  m.serve_id = serve_id;
  m.cycle = s.cycle;
  m.sim_time_s = s.world_time_s;  // the world's clock: a viewer sees a pause and a reset
  m.device_host_driving = host_driving;
  m.paused = paused;
  put3(m.device_p_m, s.input.p_world);
  m.device_q_wxyz[0] = s.input.q_world.w();
  m.device_q_wxyz[1] = s.input.q_world.x();
  m.device_q_wxyz[2] = s.input.q_world.y();
  m.device_q_wxyz[3] = s.input.q_world.z();
  put3(m.command_force_n, s.output.force_world_n);
  const std::size_t tools = std::min<std::size_t>(s.tools.size(), 5);
  m.tool_count = static_cast<std::uint16_t>(tools);
  for (std::size_t t = 0; t < tools; ++t) {
    hapsim_msg_ToolView& v = m.tools[t];
    put3(v.p_m, s.tools[t].p_world);
    put3(v.proxy_m, s.tools[t].proxy_world);
    put3(v.force_n, s.tools[t].force_world_n);
    v.rendered_force_n = t < s.tool_force_n.size() ? s.tool_force_n[t] : 0.0;
    // -1: not in the world (ToolState::present), without a field the IDL does not have.
    v.contact_count = s.tools[t].present ? s.tools[t].contact_count : -1;
  }
  put_pose(m.hand_p_m, m.hand_q_wxyz, s.hand.X_world_hand);
  for (std::size_t f = 0; f < kFingers; ++f) {
    for (std::size_t a = 0; a < kAngles; ++a) {
      m.hand_angles_rad[f * kAngles + a] = s.hand.angles_rad[f][a];
    }
  }
  if (s.teleop) {
    m.rig_present = true;
    encode_rig(*s.teleop, m.rig);
  }
  bodies_.resize(s.body_poses_world.size());
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const Iso3& X = s.body_poses_world[b];
    put3(bodies_[b].p_m, X.translation());
    const Quat q(X.linear());
    bodies_[b].q_wxyz[0] = q.w();
    bodies_[b].q_wxyz[1] = q.x();
    bodies_[b].q_wxyz[2] = q.y();
    bodies_[b].q_wxyz[3] = q.z();
  }
  deflection_m_.resize(s.deflection_m.size());
  for (std::size_t i = 0; i < deflection_m_.size(); ++i) {
    deflection_m_[i] = static_cast<float>(s.deflection_m[i]);
  }
  offsets_.clear();
  const std::size_t segments = std::min(s.positions_body.size(), rest_body_.size());
  for (std::size_t flat = 0; flat < segments; ++flat) {
    const std::vector<float>& now = s.positions_body[flat];
    const std::vector<float>& rest = rest_body_[flat];
    if (now.size() != rest.size()) {
      continue;
    }
    for (std::size_t v = 0; 3 * v + 2 < now.size(); ++v) {
      const float dx = now[3 * v] - rest[3 * v];
      const float dy = now[3 * v + 1] - rest[3 * v + 1];
      const float dz = now[3 * v + 2] - rest[3 * v + 2];
      if (std::abs(dx) > kRestTolerance_m || std::abs(dy) > kRestTolerance_m ||
          std::abs(dz) > kRestTolerance_m) {
        offsets_.push_back(hapsim_msg_VertexOffset{
            static_cast<uint32_t>(flat), static_cast<uint32_t>(v), {dx, dy, dz}});
      }
    }
  }
  contacts_.resize(std::min(s.contact_count, s.contacts.size()));
  for (std::size_t i = 0; i < contacts_.size(); ++i) {
    const WorldContact& c = s.contacts[i];
    hapsim_msg_ContactView& v = contacts_[i];
    v.tool = c.tool.value;
    v.body = c.body.value;
    v.segment = c.segment.value;  // body-local
    put3(v.point_m, c.point_world);
    put3(v.normal, c.normal_world);
    v.depth_m = c.depth_m;
    v.force_n = c.force_n;
    v.proxy = c.proxy;
  }
  point_at(m.bodies, bodies_);
  point_at(m.deflection_m, deflection_m_);
  point_at(m.offsets, offsets_);
  point_at(m.contacts, contacts_);
  return m;
}

ViewStateDecoder::ViewStateDecoder(const World& world)
    : rest_body_(make_world_snapshot(world).positions_body),
      moved_(rest_body_.size()),
      versions_(rest_body_.size(), 0),
      changed_(rest_body_.size(), false) {
  for (std::size_t b = 0; b < world.body_count(); ++b) {
    segments_per_body_.push_back(world.segment_count(b));
  }
  if (const RigController* rig = rig_controller(world.description())) {
    master_ = &rig->master();
  }
}

bool ViewStateDecoder::decode(const hapsim_msg_ViewState& m, std::uint64_t scene_hash,
                              WorldSnapshot& s, std::string& why) {
  if (m.scene_hash != scene_hash) {
    why = "made for another scene";
    return false;
  }
  if (m.tool_count != s.tools.size() || m.bodies._length != s.body_poses_world.size() ||
      m.deflection_m._length != s.deflection_m.size() ||
      s.positions_body.size() != rest_body_.size()) {
    why = "tool, body or segment count differs from this scene's";
    return false;
  }
  if (m.contacts._length > s.contacts.size()) {
    why = "more contacts than the scene can have";
    return false;
  }
  if (!std::isfinite(m.sim_time_s) || !finite3(m.device_p_m) || !finite3(m.command_force_n)) {
    why = "a non-finite number";
    return false;
  }
  // Check everything before changing anything.
  for (std::uint32_t i = 0; i < m.deflection_m._length; ++i) {
    if (!std::isfinite(m.deflection_m._buffer[i])) {
      why = "segment " + std::to_string(i) + "'s deflection is not finite";
      return false;
    }
  }
  for (std::uint32_t i = 0; i < m.offsets._length; ++i) {
    const hapsim_msg_VertexOffset& o = m.offsets._buffer[i];
    if (o.segment >= rest_body_.size() ||
        3 * static_cast<std::size_t>(o.vertex) + 2 >= rest_body_[o.segment].size() ||
        !std::isfinite(o.offset_m[0]) || !std::isfinite(o.offset_m[1]) ||
        !std::isfinite(o.offset_m[2])) {
      why = "a vertex offset out of range or not finite";
      return false;
    }
  }
  for (std::uint32_t b = 0; b < m.bodies._length; ++b) {
    const hapsim_msg_BodyPose& p = m.bodies._buffer[b];
    const Quat q(p.q_wxyz[0], p.q_wxyz[1], p.q_wxyz[2], p.q_wxyz[3]);
    if (!finite3(p.p_m) || !q.coeffs().allFinite() || std::abs(q.norm() - 1.0) > 1e-3) {
      why = "body " + std::to_string(b) +
            "'s pose is not a finite rigid motion (|q| = " + std::to_string(q.norm()) + ")";
      return false;
    }
  }
  {
    const Quat q(m.hand_q_wxyz[0], m.hand_q_wxyz[1], m.hand_q_wxyz[2], m.hand_q_wxyz[3]);
    const bool angles_finite =
        std::all_of(std::begin(m.hand_angles_rad), std::end(m.hand_angles_rad),
                    [](double a) { return std::isfinite(a); });
    if (!finite3(m.hand_p_m) || !q.coeffs().allFinite() || std::abs(q.norm() - 1.0) > 1e-3 ||
        !angles_finite) {
      why = "the hand's pose is not a finite rigid motion (|q| = " + std::to_string(q.norm()) +
            ") or a finger angle is not finite";
      return false;
    }
  }
  if (m.rig_present) {
    if (!s.teleop) {
      why = "a rig's part, for a scene without a rig";
      return false;
    }
    if (!rig_view_fits(m.rig, s.teleop->slave_q.size(), why)) {
      return false;
    }
  }
  for (std::size_t t = 0; t < m.tool_count; ++t) {
    const hapsim_msg_ToolView& v = m.tools[t];
    if (!finite3(v.p_m) || !finite3(v.proxy_m) || !finite3(v.force_n) ||
        !std::isfinite(v.rendered_force_n)) {
      why = "a tool with a non-finite number";
      return false;
    }
  }
  for (std::uint32_t i = 0; i < m.contacts._length; ++i) {
    const hapsim_msg_ContactView& c = m.contacts._buffer[i];
    if (!finite3(c.point_m) || !finite3(c.normal) || !std::isfinite(c.force_n) ||
        !std::isfinite(c.depth_m)) {
      why = "a contact with a non-finite number";
      return false;
    }
    if (c.tool < 0 || c.tool >= m.tool_count || c.body < 0 ||
        static_cast<std::size_t>(c.body) >= segments_per_body_.size() || c.segment < 0 ||
        static_cast<std::size_t>(c.segment) >=
            segments_per_body_[static_cast<std::size_t>(c.body)]) {
      why = "a contact naming a tool, body or segment the scene does not have";
      return false;
    }
  }

  s.cycle = m.cycle;
  s.time_s = m.sim_time_s;
  s.world_time_s = m.sim_time_s;
  s.input.p_world = get3(m.device_p_m);
  s.input.q_world =
      Quat(m.device_q_wxyz[0], m.device_q_wxyz[1], m.device_q_wxyz[2], m.device_q_wxyz[3]);
  s.output.force_world_n = get3(m.command_force_n);
  for (std::size_t t = 0; t < m.tool_count; ++t) {
    const hapsim_msg_ToolView& v = m.tools[t];
    s.tools[t].p_world = get3(v.p_m);
    s.tools[t].proxy_world = get3(v.proxy_m);
    s.tools[t].force_world_n = get3(v.force_n);
    s.tools[t].present = v.contact_count >= 0;
    s.tools[t].contact_count = static_cast<std::int32_t>(std::max<long>(v.contact_count, 0));
    s.tool_force_n[t] = v.rendered_force_n;
  }
  s.hand.X_world_hand = Iso3::Identity();
  s.hand.X_world_hand.linear() =
      Quat(m.hand_q_wxyz[0], m.hand_q_wxyz[1], m.hand_q_wxyz[2], m.hand_q_wxyz[3])
          .normalized()
          .toRotationMatrix();
  s.hand.X_world_hand.translation() = get3(m.hand_p_m);
  for (std::size_t f = 0; f < kFingers; ++f) {
    for (std::size_t a = 0; a < kAngles; ++a) {
      s.hand.angles_rad[f][a] = m.hand_angles_rad[f * kAngles + a];
    }
  }
  if (m.rig_present) {
    decode_rig(m.rig, master_, *s.teleop);
    s.teleop->cycle = m.cycle;
    s.teleop->time_s = m.sim_time_s;
  }
  for (std::uint32_t b = 0; b < m.bodies._length; ++b) {
    const hapsim_msg_BodyPose& p = m.bodies._buffer[b];
    Iso3 X = Iso3::Identity();
    X.linear() =
        Quat(p.q_wxyz[0], p.q_wxyz[1], p.q_wxyz[2], p.q_wxyz[3]).normalized().toRotationMatrix();
    X.translation() = get3(p.p_m);
    s.body_poses_world[b] = X;
  }
  for (std::uint32_t i = 0; i < m.deflection_m._length; ++i) {
    s.deflection_m[i] = static_cast<double>(m.deflection_m._buffer[i]);
  }
  // Put back what moved last time, then apply this message's offsets.
  std::vector<bool>& changed = changed_;
  std::fill(changed.begin(), changed.end(), false);
  for (std::size_t flat = 0; flat < moved_.size(); ++flat) {
    std::vector<float>& xyz = s.positions_body[flat];
    const std::vector<float>& rest = rest_body_[flat];
    if (xyz.size() != rest.size()) {
      xyz = rest;
    }
    for (const std::uint32_t v : moved_[flat]) {
      const auto first = static_cast<std::ptrdiff_t>(3 * static_cast<std::size_t>(v));
      std::copy_n(rest.begin() + first, 3, xyz.begin() + first);
    }
    changed[flat] = !moved_[flat].empty();
    moved_[flat].clear();
  }
  for (std::uint32_t i = 0; i < m.offsets._length; ++i) {
    const hapsim_msg_VertexOffset& o = m.offsets._buffer[i];
    std::vector<float>& xyz = s.positions_body[o.segment];
    const std::vector<float>& rest = rest_body_[o.segment];
    const std::size_t first = 3 * static_cast<std::size_t>(o.vertex);
    for (std::size_t k = 0; k < 3; ++k) {
      xyz[first + k] = rest[first + k] + o.offset_m[k];
    }
    moved_[o.segment].push_back(o.vertex);
    changed[o.segment] = true;
  }
  for (std::size_t flat = 0; flat < changed.size(); ++flat) {
    if (changed[flat]) {
      s.positions_version[flat] = ++versions_[flat];
    }
  }
  s.contact_count = m.contacts._length;
  for (std::uint32_t i = 0; i < m.contacts._length; ++i) {
    const hapsim_msg_ContactView& c = m.contacts._buffer[i];
    WorldContact& w = s.contacts[i];
    w.tool = ToolIndex{c.tool};
    w.body = BodyIndex{c.body};
    w.segment = LocalSegment{c.segment};
    w.point_world = get3(c.point_m);
    w.normal_world = get3(c.normal);
    w.depth_m = c.depth_m;
    w.force_n = c.force_n;
    w.proxy = c.proxy;
  }
  return true;
}

}  // namespace hapsim::net
