#include "hapsim/ui/teleop_viewer_session.h"

#include "hapsim/core/device_profile.h"
#include "hapsim/core/error.h"
#include "hapsim/device/interactive_device.h"
#include "hapsim/device/simulated_device.h"
#include "hapsim/render/teleop_scene.h"
#include "hapsim/runtime/world_haptic_client.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_description.h"
#if defined(HAPSIM_WITH_SPNAV)
#include "hapsim/device/spacenav_device.h"
#endif

#include <imgui.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>

namespace hapsim {

// --- MasterHandMapping ---

MasterHandMapping::MasterHandMapping(MasterArm master, const std::array<double, 3>& seed_rad)
    : master_(std::move(master)), arm_rad_(seed_rad) {
  // Position only (the master's 3 joints place the hand), tracked from the last answer: a probe
  // moves a few millimetres per frame, so the seed converges in a few iterations; the restarts
  // only matter after a jump, and bound the worst case (out of reach) to 3 × 40 iterations.
  ik_.orientation = false;
  ik_.restarts = 2;
  ik_.max_iterations = 40;
  const MasterArmGeometry& g = master_.geometry();
  const double widest = 2.0 * g.finger_m * std::sin(g.finger_open_limit_rad);
  open_finger_rad_ = master_.finger_angle_for_opening(g.finger_gap_m + widest);
}

void MasterHandMapping::set_probe_in_slave_frame(const TeleopMapping& mapping) {
  probe_in_slave_frame_ = true;
  scale_ = mapping.scale > 0.0 ? mapping.scale : 1.0;
  X_master_slave_ = mapping.X_slave_master.inverse();
  solved_for_ = Vec3::Constant(kInf);
}

Vec3 MasterHandMapping::probe_for(const std::array<double, 3>& arm_rad) const {
  const Vec3 hand = master_.hand_pose(arm_rad).translation();
  return probe_in_slave_frame_ ? Vec3(X_master_slave_.inverse() * (scale_ * hand)) : hand;
}

// haptic path
DeviceInput MasterHandMapping::master_input(const DeviceInput& probe) noexcept {
  if (probe.p_world.allFinite() && probe.p_world != solved_for_) {
    Iso3 target = Iso3::Identity();
    target.translation() =
        probe_in_slave_frame_ ? Vec3(X_master_slave_ * probe.p_world / scale_) : probe.p_world;
    std::array<double, 3> solved{};
    const IkResult r = solve_ik(master_.arm(), target, arm_rad_, solved, ik_);
    // Not reached: solve_ik leaves its best pose (the arm stretched towards the probe).
    if (std::isfinite(solved[0]) && std::isfinite(solved[1]) && std::isfinite(solved[2])) {
      arm_rad_ = solved;
    }
    reached_ = r.reached;
    solved_for_ = probe.p_world;
  }
  DeviceInput in;
  in.time_s = probe.time_s;
  in.p_world = probe.p_world;
  in.q_world = probe.q_world;
  in.buttons = probe.buttons;
  in.healthy = probe.healthy;
  in.joint_count = 3;
  in.joint_rad[0] = arm_rad_[0];
  in.joint_rad[1] = arm_rad_[1];
  in.joint_rad[2] = arm_rad_[2];
  in.finger_count = 2;
  const double finger = (probe.buttons & 1U) != 0U ? 0.0 : open_finger_rad_;
  in.finger_rad[0] = finger;
  in.finger_rad[1] = finger;
  return in;
}

// --- the session ---

namespace {

std::string format_mm(const Vec3& p_m) {
  char text[96];
  std::snprintf(text, sizeof text, "%8.1f %8.1f %8.1f", p_m.x() * 1e3, p_m.y() * 1e3,
                p_m.z() * 1e3);
  return text;
}

class TeleopViewerSession final : public ViewerSession {
 public:
  TeleopViewerSession(const ViewerConfig& config, const SceneDescription& scene) : config_(config) {
    if (!scene.is_teleop) {
      throw Error(scene.file.string(), "not a teleoperation scene");
    }
    // Contact and deformation methods are the knee world's choices; a teleop scene has its own
    // (pads vs ball, the virtual sheet), so --method and --deformation change nothing here.
    const bool sim = config.device == "sim" || config.device.rfind("sim:", 0) == 0;
    std::optional<std::filesystem::path> trajectory;
    if (config.device.rfind("sim:", 0) == 0 && config.device.size() > 4) {
      trajectory = config.device.substr(4);
    }
    RunSetupOptions setup_options;
    setup_options.load_link_meshes = true;  // the slave is drawn with its own meshes
    RunSetup setup = make_run_setup(scene,
                                    !sim         ? DeviceChoice::external()
                                    : trajectory ? DeviceChoice::trajectory(*trajectory)
                                                 : DeviceChoice::scene_script(),
                                    setup_options);
    world_ = std::move(setup.world);
    const TeleopRigDescription& rig = *world_->description().teleop;
    view_ = std::make_unique<TeleopScene>(*world_);

    // The probe starts where the master's hand is at the script's first sample, so the slave
    // starts still (the run setup solved its start joints for that pose).
    const DeviceInput& first = setup.script_start;
    const std::array<double, 3> first_arm{first.joint_rad[0], first.joint_rad[1],
                                          first.joint_rad[2]};
    // The cursor points at the slave's tool: the probe is its target in the world.
    MasterHandMapping hand_mapping(*world_->model().master(), first_arm);
    hand_mapping.set_probe_in_slave_frame(rig.mapping);
    probe_start_W_ = hand_mapping.probe_for(first_arm);
    DeviceInput start;
    start.p_world = probe_start_W_;

    const DeviceProfile& profile = *setup.profile;
    if (sim) {
      device_ = std::move(setup.device);
      device_name_ = setup.device_name;
    } else if (config.device == "mouse") {
      auto mouse = std::make_unique<InteractiveDevice>(
          profile, start, InteractiveDeviceOptions{.position_smoothing_s = 0.01});
      mouse_ = mouse.get();
      probe_ = std::move(mouse);
      device_ = std::make_unique<MasterProbeDevice>(*probe_, hand_mapping);
      device_name_ = "mouse probe as the slave tool's target (G: grasp)";
    } else if (config.device == "spacemouse") {
#if defined(HAPSIM_WITH_SPNAV)
      SpacenavOptions so;
      so.start_p_world = probe_start_W_;
      probe_ = std::make_unique<SpacenavDevice>(profile, so);
      device_ = std::make_unique<MasterProbeDevice>(*probe_, hand_mapping);
      device_name_ = "3D mouse (spacenavd) as the slave tool's target";
#else
      throw Error("3D mouse", "this build has no 3D mouse support (libspnav was not found)");
#endif
    } else {
      throw Error("device",
                  "expected mouse, sim, sim:FILE or spacemouse, got '" + config.device + "'");
    }
    title_ = scene.file.filename().string() + " — " + setup.slave_name + ", " + device_name_;
    readout_.bar_full_scale_n = rig.gripper.max_force_n;
    start_loop();
  }

  ~TeleopViewerSession() override {
    loop_->stop();
  }
  TeleopViewerSession(const TeleopViewerSession&) = delete;
  TeleopViewerSession& operator=(const TeleopViewerSession&) = delete;
  TeleopViewerSession(TeleopViewerSession&&) = delete;
  TeleopViewerSession& operator=(TeleopViewerSession&&) = delete;

  void update() override {
    TripleBuffer<WorldSnapshot>& snapshots = *client_->snapshots();
    snapshots.update();
    const TeleopSnapshot& s = *snapshots.read_slot().teleop;
    view_->update(s);

    SessionReadout& r = readout_;
    r.time_s = s.time_s;
    r.cycle = s.cycle;
    r.tools.resize(2);
    ToolReadout& tool = r.tools[0];
    tool.name = "slave tool";
    tool.p_world = s.X_world_tool.translation();
    tool.proxy_world = tool.p_world;  // no proxy: the same point (the data area hides it)
    tool.force_n = s.output.force_world_n.allFinite() ? s.output.force_world_n.norm() : 0.0;
    tool.contacts = (s.pad_force_n[0] > 0.0 ? 1 : 0) + (s.pad_force_n[1] > 0.0 ? 1 : 0);
    ToolReadout& hand = r.tools[1];
    hand.name = "master hand";
    hand.p_world = s.X_master_hand.translation();  // the master's base frame
    hand.proxy_world = hand.p_world;
    hand.force_n = 0.0;
    hand.contacts = 0;
    r.contact_count = static_cast<std::size_t>(tool.contacts);

    r.bars.clear();
    r.bars.emplace_back("grasp", s.grasp_force_n);
    r.bars.emplace_back("pad 1", s.pad_force_n[0]);
    r.bars.emplace_back("pad 2", s.pad_force_n[1]);
    // The sheet's deepest dent (≥ 0: a node resting a hair above its rest height is no dent).
    const double dent_m = s.sheet_depth_m > 0.0 ? s.sheet_depth_m : 0.0;
    r.max_deflection_m = dent_m;

    char text[160];
    r.lines.clear();
    r.lines.emplace_back("ball (mm)", format_mm(s.ball_p_world) + (s.held ? "  held" : "  free"));
    std::snprintf(text, sizeof text, "%.1f mm, grasp %.2f N", s.gripper_width_m * 1e3,
                  s.grasp_force_n);
    r.lines.emplace_back("gripper", text);
    std::snprintf(text, sizeof text, "%.2f", dent_m * 1e3);
    r.lines.emplace_back("sheet deepest dent (mm)", text);
    std::string joints;
    for (const double q : s.slave_q) {
      std::snprintf(text, sizeof text, "%s%.1f", joints.empty() ? "" : " ",
                    q * 180.0 / std::numbers::pi);
      joints += text;
    }
    r.lines.emplace_back("slave joints (deg)", joints);
    std::snprintf(text, sizeof text, "%.1f %.1f %.1f, fingers %.1f %.1f",
                  s.master_joint_rad[0] * 180.0 / std::numbers::pi,
                  s.master_joint_rad[1] * 180.0 / std::numbers::pi,
                  s.master_joint_rad[2] * 180.0 / std::numbers::pi,
                  s.master_finger_rad[0] * 180.0 / std::numbers::pi,
                  s.master_finger_rad[1] * 180.0 / std::numbers::pi);
    r.lines.emplace_back("master joints (deg)", text);
    std::string torques;
    for (int j = 0; j < s.output.joint_count; ++j) {
      std::snprintf(text, sizeof text, "%s%.3f", torques.empty() ? "" : " ",
                    s.output.joint_torque_nm[static_cast<std::size_t>(j)]);
      torques += text;
    }
    r.lines.emplace_back("master torques (N·m)", torques.empty() ? "-" : torques);
  }

  RenderScene& render_scene() override {
    return view_->scene();
  }
  Box3 bounds_W() const override {
    return view_->rest_bounds_W();
  }
  const SessionReadout& readout() const override {
    return readout_;
  }
  HapticLoopStatus loop_status() const override {
    return loop_->status();
  }
  InteractiveDevice* mouse_device() override {
    return mouse_;
  }
  Vec3 probe_start_W() const override {
    return probe_start_W_;
  }
  const std::string& device_name() const override {
    return device_name_;
  }
  const std::string& title() const override {
    return title_;
  }

  void set_paused(bool paused) override {
    paused_ = paused;
    client_->set_paused(paused);
  }

  // The loop stops, the world goes back to its start (slave, ball and sheet as the scene starts
  // them) and a new client and loop start at cycle 0 — so the scripted master starts its script
  // again, in step with the slave. The probe stays where the user left it.
  void reset() override {
    loop_->stop();
    loop_.reset();
    client_.reset();
    world_->reset();
    start_loop();
  }

  bool set_recording(const std::filesystem::path* path, std::string& error) override {
    if (path == nullptr) {
      return true;
    }
    // The recording format (device/recording.h) holds a knee World's cycles.
    error = "recording teleoperation sessions is not supported yet";
    return false;
  }
  bool recording() const override {
    return false;
  }

  void draw_controls() override {
    TeleopSceneOptions o = view_->options();
    bool changed = ImGui::Checkbox("master arm", &o.show_master);
    ImGui::SameLine();
    changed |= ImGui::Checkbox("joints", &o.show_joints);
    if (changed) {
      view_->set_options(o);
    }
    if (mouse_ != nullptr) {
      ImGui::TextWrapped(
          "The probe is the master's hand (its base frame): drag to move it, wheel for depth, G "
          "closes or opens the grasp.");
    }
    const TeleopRigDescription& d = *world_->description().teleop;
    ImGui::Text("mapping scale %.2f, gripper %.0f mm / %.0f N", d.mapping.scale,
                d.follower.gripper_max_width_m * 1e3, d.gripper.max_force_n);
  }

 private:
  void start_loop() {
    client_ = std::make_unique<WorldHapticClient>(*world_);
    client_->set_paused(paused_);
    loop_ = std::make_unique<HapticLoop>(*device_, *client_);
    loop_->start();
  }

  ViewerConfig config_;
  std::unique_ptr<World> world_;  // the render scene refers to it
  std::unique_ptr<TeleopScene> view_;
  std::unique_ptr<Device> probe_;  // the mouse or 3D mouse behind device_ (null for sim)
  InteractiveDevice* mouse_ = nullptr;
  std::unique_ptr<Device> device_;
  std::unique_ptr<WorldHapticClient> client_;
  std::unique_ptr<HapticLoop> loop_;
  SessionReadout readout_;
  Vec3 probe_start_W_ = Vec3::Zero();
  bool paused_ = false;
  std::string device_name_;
  std::string title_;
};

}  // namespace

std::unique_ptr<ViewerSession> make_teleop_viewer_session(const ViewerConfig& config,
                                                          const SceneDescription& scene) {
  return std::make_unique<TeleopViewerSession>(config, scene);
}

}  // namespace hapsim
