#include "hapsim/ui/world_viewer_session.h"

#include "hapsim/rig/rig_controller.h"
#include "hapsim/ui/world_readout.h"

#include "hapsim/core/error.h"
#include "hapsim/device/interactive_device.h"
#include "hapsim/device/master_probe_device.h"
#include "hapsim/device/plugin_device.h"
#include "hapsim/device/recording.h"
#include "hapsim/device/space_mouse_axes.h"
#include "hapsim/kinematics/hand_model.h"
#include "hapsim/render/assessment_markers.h"
#include "hapsim/render/force_scale.h"
#include "hapsim/render/world_scene.h"
#include "hapsim/runtime/fem_thread.h"
#include "hapsim/runtime/world_haptic_client.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/training/assessment_scorer.h"
#if defined(HAPSIM_WITH_SPNAV)
#include "hapsim/device/spacenav_device.h"
#endif

#include <imgui.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <numbers>
#include <optional>
#include <vector>

namespace hapsim {
namespace {

ContactMethod method_from(const std::string& name) {
  if (const auto m = parse_contact_method(name)) {
    return *m;
  }
  throw Error("contact method", "expected exact, spheretree or knee, got '" + name + "'");
}

// In front of the scene from the default camera (+Y, a little −X), a finger's width clear. For a
// glove the probe is the tracker: placed so that the fingertip nearest the scene (straight
// fingers, the device's orientation) lands on that spot and the others are farther out: the hand
// starts clear of the body.
Vec3 probe_start_for(const WorldDescription& world, const Box3& bounds_world) {
  const Vec3 towards_viewer = Vec3(-0.2, 1.0, 0.0).normalized();
  Vec3 p =
      bounds_world.center() + towards_viewer * (0.5 * bounds_world.sizes().head<2>().norm() + 0.03);
  if (world.has_hand) {
    const HandModel hand(world.hand);
    const auto tips = hand.fingertips_world(GloveReading{});
    Vec3 nearest = tips[0];
    for (const Vec3& tip : tips) {
      nearest = tip.dot(towards_viewer) < nearest.dot(towards_viewer) ? tip : nearest;
    }
    p -= nearest;
  }
  return p;
}

// The viewer's session for every scene (architecture.md#viewer): the World on the real-time
// haptic loop with its device (the viewer's mouse probe, the scene's script or a trajectory, a 3D
// mouse, a driver plugin's device; for a teleoperation rig the probe is the slave tool's target,
// turned into master joints by MasterProbeDevice); one client, one snapshot, one recorder. What is
// drawn and read out differs per kind of thing: bodies and tools, or a rig (its readout and
// controls); one WorldScene draws both.
class WorldViewerSession final : public ViewerSession {
 public:
  WorldViewerSession(const ViewerConfig& config, SceneDescription scene) : config_(config) {
    RunSetupOptions setup_options;
    if (!config.method.empty()) {
      setup_options.method = method_from(config.method);
    }
    if (config.deformation == "none") {
      setup_options.rigid = true;
    } else if (config.deformation != "deflection") {
      throw Error("deformation", "expected deflection or none, got '" + config.deformation + "'");
    }
    const bool sim = config.device == "sim" || config.device.rfind("sim:", 0) == 0;
    std::optional<std::filesystem::path> trajectory;
    if (sim && config.device.size() > 4) {
      trajectory = config.device.substr(4);
    }
    // A driver plugin is opened before the world is built: the world renders no stiffer than its
    // device is rated for (as `hapsim run --device plugin:` does).
    const std::optional<std::filesystem::path> plugin_path =
        plugin_path_from_device_spec(config.device);
    std::unique_ptr<PluginDevice> plugin;
    if (plugin_path) {
      plugin = open_plugin_device(*plugin_path, config.driver_config);
      setup_options.external_profile = &plugin->profile();
    }
    RunSetup setup = make_run_setup(std::move(scene),
                                    !sim         ? DeviceChoice::external()
                                    : trajectory ? DeviceChoice::trajectory(*trajectory)
                                                 : DeviceChoice::scene_script(),
                                    setup_options);
    scene_ = std::move(setup.scene);
    world_ = std::move(setup.world);
    const DeviceProfile& profile = *setup.profile;
    materials_.reserve(scene_.world.materials.size());
    for (const MaterialDescription& m : scene_.world.materials) {
      materials_.push_back(m.contact);
    }
    // The position a mouse or 3D mouse starts at, and what turns it into the device's input.
    std::optional<MasterHandMapping> hand_mapping;
    view_ = std::make_unique<WorldScene>(*world_);
    if (rig_state(*world_) != nullptr) {
      // The probe starts where the master's hand is at the script's first sample, so the slave
      // starts still (the run setup solved its start joints for that pose). The cursor points at
      // the slave's tool: the probe is its target in the world.
      const DeviceInput& first = setup.script_start;
      const std::array<double, 3> first_arm{first.joint_rad[0], first.joint_rad[1],
                                            first.joint_rad[2]};
      hand_mapping.emplace(rig_controller(world_->description())->master(), first_arm);
      hand_mapping->set_probe_in_slave_frame(rig_description(world_->description())->mapping);
      probe_start_world_ = hand_mapping->probe_for(first_arm);
    } else {
      probe_start_world_ = probe_start_for(scene_.world, view_->rest_bounds_world());
    }
    const std::string target = hand_mapping ? " as the slave tool's target" : "";
    if (config.device == "mouse") {
      DeviceInput start;
      start.p_world = probe_start_world_;
      auto mouse = std::make_unique<InteractiveDevice>(
          profile, start, InteractiveDeviceOptions{.position_smoothing_s = 0.01});
      mouse_ = mouse.get();
      probe_ = std::move(mouse);
      device_name_ = "mouse probe" + target + " (" + profile.name + " limits" +
                     (hand_mapping ? "; G: grasp)" : ")");
    } else if (sim) {
      device_ = std::move(setup.device);
      device_name_ = setup.device_name;
    } else if (plugin) {
      if (hand_mapping) {
        throw Error("--device " + config.device,
                    scene_.file.filename().string() +
                        " is a teleoperation scene, whose master arm its script drives; a plugin "
                        "drives probe and glove scenes");
      }
      const DeviceProfile& rated = plugin->profile();
      char rating[128];
      std::snprintf(rating, sizeof rating, "rated %.1f N, %.0f N/m", rated.max_force_n,
                    rated.max_stiffness_n_per_m);
      device_name_ =
          "plugin '" + plugin->driver_name() + "' (" + plugin_path->string() + ", " + rating + ")";
      device_ = std::move(plugin);
    } else if (config.device == "spacemouse") {
#if defined(HAPSIM_WITH_SPNAV)
      SpacenavOptions so;
      so.start_p_world = probe_start_world_;
      auto space_mouse = std::make_unique<SpacenavDevice>(profile, so);
      space_mouse_ = space_mouse.get();
      probe_ = std::move(space_mouse);
      device_name_ = "3D mouse (spacenavd)" + target;
#else
      throw Error("3D mouse", "this build has no 3D mouse support (libspnav was not found)");
#endif
    } else {
      throw Error("device", "expected mouse, sim, sim:FILE, spacemouse or plugin:PATH.so, got '" +
                                config.device + "'");
    }
    if (probe_) {
      // A rig's master wants joints: the probe's position goes through the master's IK.
      if (hand_mapping) {
        device_ = std::make_unique<MasterProbeDevice>(*probe_, *hand_mapping);
      } else {
        device_ = std::move(probe_);
      }
    }
    title_ = scene_.file.filename().string() + " — " +
             (setup.slave_name.empty() ? "" : setup.slave_name + ", ") + device_name_;
    readout_.rated_force_n = rig_state(*world_) != nullptr
                                 ? rig_description(world_->description())->gripper.max_force_n
                                 : device_rated_force_n(profile);
    readout_.bar_full_scale_n =
        force_display_scale_n(world_->description(), readout_.rated_force_n);
    WorldSceneOptions o = view_->options();
    o.force_full_scale_n = readout_.bar_full_scale_n;
    view_->set_options(o);
    if (scene_.has_assessment) {
      // Scored from the records this thread drains (never the haptic path); the landmarks marked
      // where the default view (the knee from the front, a little medial) sees them.
      teleop_target_world_ = setup.teleop_target_world;
      script_length_s_ = sim ? setup.duration_s : 0.0;
      scorer_ = std::make_unique<AssessmentScorer>(scene_.assessment, *world_, scene_.run.dt_s,
                                                   teleop_target_world_);
      std::vector<Iso3> X_world_body;
      for (std::size_t b = 0; b < world_->body_count(); ++b) {
        X_world_body.push_back(world_->body_pose(b));
      }
      landmark_markers_ =
          landmark_marker_points(world_->description(), X_world_body, scene_.assessment,
                                 Vec3(-0.35, 0.9, 0.3).normalized());
      marker_m_ = std::clamp(0.02 * view_->rest_bounds_world().sizes().norm(), 0.004, 0.03);
    }
    start_loop();
  }
  ~WorldViewerSession() override {
    loop_->stop();
    fem_thread_.reset();  // nothing steps the FEM bodies while the world is not stepped
    if (recorder_) {
      drain_records();  // the last cycles too
      recorder_->close();
    }
  }
  WorldViewerSession(const WorldViewerSession&) = delete;
  WorldViewerSession& operator=(const WorldViewerSession&) = delete;
  WorldViewerSession(WorldViewerSession&&) = delete;
  WorldViewerSession& operator=(WorldViewerSession&&) = delete;

  // Every cycle's record: to the recorder while recording, else let go.
  void drain_records() {
    SpscRing<CycleRecord>& records = *client_->records();
    while (const CycleRecord* r = records.front()) {
      if (scorer_) {
        scorer_->add(*r);
      }
      if (recorder_) {
        if (!recorder_->record(to_recorded_frame(*r, device_->profile()))) {
          ++recorded_dropped_;
        }
        // Every 100 ms of the session at most (off the haptic thread: this is the graphics loop),
        // so a killed viewer loses little.
        if (recorder_->flush_due()) {
          recorder_->flush();
        }
      }
      records.pop();
    }
  }

  void update() override {
    drain_records();
    TripleBuffer<WorldSnapshot>& snapshots = *client_->snapshots();
    snapshots.update();
    const WorldSnapshot& s = snapshots.read_slot();
    view_->update(s);
    view_->update_fem_surfaces(*world_);
    if (s.teleop) {
      update_rig(s, *s.teleop);
    } else {
      fill_world_readout(*world_, *view_, s, readout_);
    }
    update_assessment();
  }

  // The landmarks (found green, missed grey, breaches red) and the score: "so far" while the
  // session runs, final once a scripted device's run has ended (the result recomputed at most
  // once a second of session time: it copies the force series).
  void update_assessment() {
    if (!scorer_) {
      return;
    }
    const double dt_s = scene_.run.dt_s;
    const double t_s = static_cast<double>(scorer_->cycles()) * dt_s;
    const bool finished = script_length_s_ > 0.0 && t_s >= script_length_s_ - 0.5 * dt_s;
    if (!assessment_ || t_s - assessed_at_s_ >= 1.0 || (finished && !final_)) {
      assessment_ = std::make_unique<AssessmentResult>(scorer_->finish());
      assessed_at_s_ = t_s;
      final_ = finished;
    }
    if (show_landmarks_) {
      std::vector<bool> found;
      for (std::size_t i = 0; i < scene_.assessment.landmarks.size(); ++i) {
        found.push_back(scorer_->landmark_found(i));
      }
      std::vector<Vec3> breaches;
      for (const BreachResult& b : assessment_->breaches) {
        breaches.push_back(b.point_world);
      }
      add_assessment_markers(view_->scene(), scene_.assessment, landmark_markers_, found, breaches,
                             marker_m_);
    }
    char text[160];
    if (!assessment_->landmarks.empty()) {
      std::snprintf(text, sizeof text, "%zu of %zu", assessment_->landmarks_found(),
                    assessment_->landmarks.size());
      readout_.lines.emplace_back("landmarks found", text);
    }
    std::snprintf(text, sizeof text, "%zu", assessment_->breaches.size());
    readout_.lines.emplace_back("force-limit breaches", text);
    std::snprintf(text, sizeof text, "%.1f / %.0f%s", assessment_->score.value,
                  assessment_->score.max, final_ ? " (final)" : " (so far)");
    readout_.lines.emplace_back("score", text);
  }

  RenderScene& render_scene() override {
    return view_->scene();
  }
  Box3 bounds_world() const override {
    return view_->rest_bounds_world();
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
  SpaceMouseSource* space_mouse() override {
    return space_mouse_;
  }
  Vec3 probe_start_world() const override {
    return probe_start_world_;
  }
  const std::string& device_name() const override {
    return device_name_;
  }
  const std::vector<std::string>& warnings() const override {
    return scene_.warnings;
  }
  const std::string& title() const override {
    return title_;
  }
  void set_paused(bool paused) override {
    const bool pausing = paused && !paused_;
    paused_ = paused;
    client_->set_paused(paused);
    if (pausing && recorder_) {
      // Cycles after a pause would not replay as one run (the world forgets the tool's motion
      // when it resumes): the recording ends here, as on a reset.
      drain_records();
      recorder_->close();
      recorder_.reset();
    }
  }
  // The loop stops, the world goes back to its start (tools, deformation; a rig's slave, ball and
  // sheet) and a new client and loop start at cycle 0 — so a scripted device starts its script
  // again, in step with the world. The probe stays where the user left it.
  void reset() override {
    loop_->stop();
    fem_thread_.reset();  // nothing steps the FEM bodies while the world is not stepped
    if (recorder_) {
      // Cycles after a reset would not replay on one world: the recording ends here.
      drain_records();
      recorder_->close();
      recorder_.reset();
    }
    drain_records();
    loop_.reset();
    client_.reset();
    world_->reset();
    if (scorer_) {
      // The world starts again: so does its assessment.
      scorer_ = std::make_unique<AssessmentScorer>(scene_.assessment, *world_, scene_.run.dt_s,
                                                   teleop_target_world_);
      assessment_.reset();
      final_ = false;
    }
    start_loop();
  }

  bool set_recording(const std::filesystem::path* path, std::string& error) override {
    if (path == nullptr) {
      if (recorder_) {
        drain_records();
        recorder_->close();
        recorder_.reset();
      }
      return true;
    }
    try {
      // The hash of what the haptic thread runs: the world's description (immutable) with the
      // materials as edited here (this thread's copy; the world's own is the haptic thread's).
      WorldDescription running = world_->description();
      for (std::size_t m = 0; m < materials_.size(); ++m) {
        running.materials[m].contact = materials_[m];
      }
      auto recorder = std::make_unique<SessionRecorder>(
          *path, content_hash(running), 8192, SessionRecorder::Overflow::kDrop, scene_.file);
      // A recording starts from the scene's start (the world reset, cycle 0), so that replaying
      // it on a fresh world (hapsim run --replay) reproduces it bit for bit.
      reset();
      recorder_ = std::move(recorder);
      recorded_dropped_ = 0;
      return true;
    } catch (const std::exception& e) {
      error = e.what();
      return false;
    }
  }
  bool recording() const override {
    return recorder_ != nullptr;
  }

  bool set_material_contact(std::size_t material, const ContactMaterial& contact) override {
    // A recording names the materials it was made with (its hash): no edits during one.
    if (material >= materials_.size() || recorder_) {
      return false;
    }
    materials_[material] = contact;
    return client_->request_material(static_cast<std::uint32_t>(material), contact);
  }

  void set_knee_overlays(bool influence_spheres, bool contact_vertices) override {
    WorldSceneOptions o = view_->options();
    o.show_influence_spheres = influence_spheres;
    o.show_contact_vertices = contact_vertices;
    view_->set_options(o);
  }
  void draw_controls() override {
    if (rig_state(*world_) != nullptr) {
      draw_rig_controls();
      return;
    }
    draw_world_display_controls(*view_);
    if (scorer_) {
      ImGui::Checkbox("landmarks (found green, missed grey)", &show_landmarks_);
    }
    if (ImGui::CollapsingHeader("Stiffness and limits")) {
      if (recorder_) {
        ImGui::TextWrapped(
            "Recording: stop it to change materials (a recording names its "
            "materials).");
      }
      for (std::size_t m = 0; m < materials_.size(); ++m) {
        ContactMaterial& c = materials_[m];
        ImGui::PushID(static_cast<int>(m));
        ImGui::TextUnformatted(scene_.world.materials[m].name.c_str());
        auto k = static_cast<float>(c.stiffness_n_per_m);
        auto f = static_cast<float>(c.max_force_n);
        auto x = static_cast<float>(c.max_penetration_m * 1e3);
        bool edited = ImGui::SliderFloat("k (N/m)", &k, 10.0f, 10000.0f, "%.0f",
                                         ImGuiSliderFlags_Logarithmic);
        edited |= ImGui::SliderFloat("max force (N)", &f, 0.1f, 40.0f, "%.1f");
        edited |= ImGui::SliderFloat("max depth (mm)", &x, 0.5f, 30.0f, "%.1f");
        if (edited) {
          ContactMaterial edited_material = c;
          edited_material.stiffness_n_per_m = k;
          edited_material.max_force_n = f;
          edited_material.max_penetration_m = 1e-3 * static_cast<double>(x);
          set_material_contact(m, edited_material);
        }
        ImGui::PopID();
      }
    }
  }

 private:
  void start_loop() {
    WorldHapticClientOptions co;
    co.record_capacity = 1024;  // drained every frame: 1 s of slack at 1 fps
    client_ = std::make_unique<WorldHapticClient>(*world_, co);
    client_->set_paused(paused_);
    loop_ = std::make_unique<HapticLoop>(*device_, *client_);
    loop_->start();
    fem_thread_ = std::make_unique<FemThread>(*world_);  // FEM bodies step on their own thread
  }

  // The rig's readout: the slave tool and the master hand, grasp and pad forces, ball, gripper,
  // the sheet's dent, the slave's and the master's joints and the torques sent.
  void update_rig(const WorldSnapshot& world, const TeleopSnapshot& s) {
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

    const TeleopRigDescription& rig = *rig_description(world_->description());
    r.bars.clear();
    char text[160];
    r.lines.clear();
    if (rig.carried_tool < world.tools.size()) {
      // A carried tool (tele-palpation): its contact force is what the master's hand feels.
      const ToolState& carried = world.tools[rig.carried_tool];
      tool.force_n = carried.force_world_n.allFinite() ? carried.force_world_n.norm() : 0.0;
      tool.contacts = carried.contact_count;
      r.contact_count = static_cast<std::size_t>(std::max(0, carried.contact_count));
      r.bars.emplace_back(world_->description().tools[rig.carried_tool].name, tool.force_n);
      r.max_deflection_m = 0.0;
    }
    if (rig.ball_body != TeleopRigDescription::kNoBody) {
      r.bars.emplace_back("grasp", s.grasp_force_n);
      r.bars.emplace_back("pad 1", s.pad_force_n[0]);
      r.bars.emplace_back("pad 2", s.pad_force_n[1]);
      const Vec3 ball_p_world = world.body_poses_world[rig.ball_body].translation();
      r.lines.emplace_back("ball (mm)", format_mm(ball_p_world) + (s.held ? "  held" : "  free"));
      std::snprintf(text, sizeof text, "%.1f mm, grasp %.2f N", s.gripper_width_m * 1e3,
                    s.grasp_force_n);
      r.lines.emplace_back("gripper", text);
    }
    if (rig.sheet_body != TeleopRigDescription::kNoBody) {
      // The sheet's deepest dent (≥ 0: a node resting a hair above its rest height is no dent).
      const double dent_m = s.sheet_depth_m > 0.0 ? s.sheet_depth_m : 0.0;
      r.max_deflection_m = dent_m;
      std::snprintf(text, sizeof text, "%.2f", dent_m * 1e3);
      r.lines.emplace_back("sheet deepest dent (mm)", text);
    }
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

  void draw_rig_controls() {
    WorldSceneOptions o = view_->options();
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
    const TeleopRigDescription& d = *rig_description(world_->description());
    ImGui::Text("mapping scale %.2f, gripper %.0f mm / %.0f N", d.mapping.scale,
                d.follower.gripper_max_width_m * 1e3, d.gripper.max_force_n);
  }

  ViewerConfig config_;
  SceneDescription scene_;
  std::unique_ptr<World> world_;
  std::unique_ptr<WorldScene> view_;
  std::unique_ptr<Device> probe_;            // a mouse or 3D mouse behind a rig's MasterProbeDevice
  SpaceMouseSource* space_mouse_ = nullptr;  // the 3D mouse, owned by probe_ or device_
  std::unique_ptr<Device> device_;
  InteractiveDevice* mouse_ = nullptr;
  std::unique_ptr<WorldHapticClient> client_;
  std::unique_ptr<HapticLoop> loop_;
  std::unique_ptr<FemThread> fem_thread_;
  std::unique_ptr<SessionRecorder> recorder_;
  std::size_t recorded_dropped_ = 0;
  std::vector<ContactMaterial> materials_;  // the UI's copy (the world's is the haptic thread's)
  SessionReadout readout_;
  Vec3 probe_start_world_ = Vec3::Zero();
  std::string device_name_;
  std::string title_;
  bool paused_ = false;
  // The scene's assessment, when it has one (docs/assessment.md).
  std::unique_ptr<AssessmentScorer> scorer_;
  std::unique_ptr<AssessmentResult> assessment_;
  std::optional<Vec3> teleop_target_world_;
  std::vector<Vec3> landmark_markers_;
  double marker_m_ = 0.0;
  double script_length_s_ = 0.0;  // a scripted device's run (0: open-ended)
  double assessed_at_s_ = 0.0;
  bool final_ = false;
  bool show_landmarks_ = true;
};

}  // namespace

std::unique_ptr<ViewerSession> make_world_viewer_session(const ViewerConfig& config,
                                                         const SceneDescription& scene) {
  return std::make_unique<WorldViewerSession>(config, scene);
}

}  // namespace hapsim
