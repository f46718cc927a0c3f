#include "hapsim/ui/world_viewer_session.h"

#include "hapsim/core/error.h"
#include "hapsim/device/interactive_device.h"
#include "hapsim/device/recording.h"
#include "hapsim/kinematics/hand_model.h"
#include "hapsim/render/world_scene.h"
#include "hapsim/runtime/world_haptic_client.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"
#if defined(HAPSIM_WITH_SPNAV)
#include "hapsim/device/spacenav_device.h"
#endif

#include <imgui.h>

#include <algorithm>
#include <cstdio>

namespace hapsim {
namespace {

ContactMethod method_from(const std::string& name) {
  if (const auto m = parse_contact_method(name)) {
    return *m;
  }
  throw Error("contact method", "expected exact, spheretree or knee, got '" + name + "'");
}

std::string format_mm(const Vec3& p_m) {
  char text[96];
  std::snprintf(text, sizeof text, "%8.1f %8.1f %8.1f", p_m.x() * 1e3, p_m.y() * 1e3,
                p_m.z() * 1e3);
  return text;
}

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
    RunSetup setup = make_run_setup(std::move(scene),
                                    !sim         ? DeviceChoice::external()
                                    : trajectory ? DeviceChoice::trajectory(*trajectory)
                                                 : DeviceChoice::scene_script(),
                                    setup_options);
    scene_ = std::move(setup.scene);
    world_ = std::move(setup.world);
    const DeviceProfile& profile = *setup.profile;
    view_ = std::make_unique<WorldScene>(*world_);
    materials_.reserve(scene_.world.materials.size());
    for (const MaterialDescription& m : scene_.world.materials) {
      materials_.push_back(m.contact);
    }

    const Box3 b = view_->rest_bounds_W();
    // In front of the scene from the default camera (+Y, a little −X), a finger's width clear.
    probe_start_W_ =
        b.center() + Vec3(-0.2, 1.0, 0.0).normalized() * (0.5 * b.sizes().head<2>().norm() + 0.03);
    if (scene_.world.has_hand) {
      // A glove drives a hand: the probe is the tracker. Place it so that the fingertip nearest
      // the scene (straight fingers, the device's orientation) lands on that spot and the others
      // are farther out: the hand starts clear of the body.
      const HandModel hand(scene_.world.hand);
      const Vec3 towards_viewer = Vec3(-0.2, 1.0, 0.0).normalized();
      const auto tips = hand.fingertips_world(GloveReading{});
      Vec3 nearest = tips[0];
      for (const Vec3& tip : tips) {
        nearest = tip.dot(towards_viewer) < nearest.dot(towards_viewer) ? tip : nearest;
      }
      probe_start_W_ -= nearest;
    }
    if (config.device == "mouse") {
      DeviceInput start;
      start.p_world = probe_start_W_;
      auto mouse = std::make_unique<InteractiveDevice>(
          profile, start, InteractiveDeviceOptions{.position_smoothing_s = 0.01});
      mouse_ = mouse.get();
      device_ = std::move(mouse);
      device_name_ = "mouse probe (" + profile.name + " limits)";
    } else if (sim) {
      device_ = std::move(setup.device);
      const std::string what = trajectory ? "trajectory " + trajectory->string() : "scene script";
      device_name_ = profile.name == "simulated" ? what + " (simulated device)"
                                                 : what + " (simulated " + profile.name + ")";
    } else if (config.device == "spacemouse") {
#if defined(HAPSIM_WITH_SPNAV)
      SpacenavOptions so;
      so.start_p_world = probe_start_W_;
      device_ = std::make_unique<SpacenavDevice>(profile, so);
      device_name_ = "3D mouse (spacenavd)";
#else
      throw Error("3D mouse", "this build has no 3D mouse support (libspnav was not found)");
#endif
    } else {
      throw Error("device",
                  "expected mouse, sim, sim:FILE or spacemouse, got '" + config.device + "'");
    }
    WorldHapticClientOptions co;
    co.record_capacity = 1024;  // drained every frame: 1 s of slack at 1 fps
    client_ = std::make_unique<WorldHapticClient>(*world_, co);
    loop_ = std::make_unique<HapticLoop>(*device_, *client_);
    title_ = scene_.file.filename().string() + " — " + device_name_;
    readout_.bar_full_scale_n = profile.finger_count > 0 && profile.max_finger_force_n > 0.0
                                    ? std::max(profile.max_finger_force_n, profile.max_force_n)
                                    : profile.max_force_n;
    loop_->start();
  }

  ~WorldViewerSession() override {
    loop_->stop();
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
      if (recorder_) {
        if (!recorder_->record(to_recorded_frame(*r))) {
          ++recorded_dropped_;
        }
        if (recorder_->frames_buffered() >= recorder_->capacity_frames() / 2) {
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
    const WorldDescription& d = world_->description();
    readout_.time_s = s.time_s;
    readout_.cycle = s.cycle;
    readout_.tools.resize(s.tools.size());
    readout_.bars.clear();
    readout_.lines.clear();
    for (std::size_t t = 0; t < s.tools.size(); ++t) {
      ToolReadout& r = readout_.tools[t];
      r.name = d.tools[t].name;
      r.p_world = s.tools[t].p_world;
      r.proxy_world = s.tools[t].proxy_world;
      r.force_n = s.tool_force_n[t];
      r.contacts = s.tools[t].contact_count;
      readout_.bars.emplace_back(r.name, r.force_n);
    }
    readout_.contact_count = s.contact_count;
    readout_.max_deflection_m = 0.0;
    for (const double x : s.deflection_m) {
      readout_.max_deflection_m = std::max(readout_.max_deflection_m, x);
    }
    // What is touched now.
    std::string touched;
    for (std::size_t i = 0; i < s.contact_count; ++i) {
      const WorldContact& c = s.contacts[i];
      const std::string& label = view_->segment_label(world_->flat_segment(
          static_cast<std::size_t>(c.body), static_cast<std::size_t>(c.segment)));
      if (touched.find(label) == std::string::npos) {
        touched += (touched.empty() ? "" : ", ") + label;
      }
    }
    readout_.lines.emplace_back("touching", touched.empty() ? "-" : touched);
    readout_.lines.emplace_back("device pose (mm)", format_mm(s.input.p_world));
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
    client_->set_paused(paused);
  }
  void reset() override {
    client_->request_reset();
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
      // The hash of what the haptic thread runs: the scene with the materials as edited here
      // (computed from this thread's copy; the world's own is the haptic thread's).
      WorldDescription running = scene_.world;
      for (std::size_t m = 0; m < materials_.size(); ++m) {
        running.materials[m].contact = materials_[m];
      }
      drain_records();  // start with the next cycle
      recorder_ = std::make_unique<SessionRecorder>(*path, content_hash(running), 8192);
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

  void draw_controls() override {
    WorldSceneOptions o = view_->options();
    bool changed = false;
    int colouring = static_cast<int>(o.colouring);
    ImGui::TextUnformatted("Colours");
    changed |= ImGui::RadioButton("tissue", &colouring, 0);
    ImGui::SameLine();
    changed |= ImGui::RadioButton("segments", &colouring, 1);
    ImGui::SameLine();
    changed |= ImGui::RadioButton("groups", &colouring, 2);
    o.colouring = static_cast<SegmentColouring>(colouring);
    changed |= ImGui::SliderInt("sphere-tree level", &o.sphere_tree_level, -1, 6,
                                o.sphere_tree_level < 0 ? "off" : "%d");
    changed |= ImGui::Checkbox("proxies", &o.show_proxies);
    ImGui::SameLine();
    changed |= ImGui::Checkbox("force arrows", &o.show_force_arrows);
    if (changed) {
      view_->set_options(o);
    }
    if (ImGui::CollapsingHeader("Segments", ImGuiTreeNodeFlags_DefaultOpen)) {
      for (std::size_t i = 0; i < view_->segment_count(); ++i) {
        bool visible = view_->segment_visible(i);
        if (ImGui::Checkbox(view_->segment_label(i).c_str(), &visible)) {
          view_->set_segment_visible(i, visible);
        }
      }
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
  ViewerConfig config_;
  SceneDescription scene_;
  std::unique_ptr<World> world_;
  std::unique_ptr<WorldScene> view_;
  std::unique_ptr<Device> device_;
  InteractiveDevice* mouse_ = nullptr;
  std::unique_ptr<WorldHapticClient> client_;
  std::unique_ptr<HapticLoop> loop_;
  std::unique_ptr<SessionRecorder> recorder_;
  std::size_t recorded_dropped_ = 0;
  std::vector<ContactMaterial> materials_;  // the UI's copy (the world's is the haptic thread's)
  SessionReadout readout_;
  Vec3 probe_start_W_ = Vec3::Zero();
  std::string device_name_;
  std::string title_;
};

}  // namespace

std::unique_ptr<ViewerSession> make_world_viewer_session(const ViewerConfig& config,
                                                         const SceneDescription& scene) {
  return std::make_unique<WorldViewerSession>(config, scene);
}

}  // namespace hapsim
