#include "hapsim/ui/net_viewer_session.h"

#include "hapsim/core/error.h"
#include "hapsim/core/install_dirs.h"
#include "hapsim/net/command_sender.h"
#include "hapsim/net/dds_domain.h"
#include "hapsim/net/loaned_reader.h"
#include "hapsim/net/participant.h"
#include "hapsim/net/scene_hash.h"
#include "hapsim/net/scene_info.h"
#include "hapsim/net/served_scene.h"
#include "hapsim/net/view_state_codec.h"
#include "hapsim/render/force_scale.h"
#include "hapsim/render/world_scene.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/ui/world_readout.h"

#include <imgui.h>

#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <optional>
#include <thread>

namespace hapsim {
namespace {

std::string hex(std::uint64_t value) {
  char text[24];
  std::snprintf(text, sizeof text, "%016" PRIx64, value);
  return text;
}

class NetViewerSession final : public ViewerSession {
 public:
  explicit NetViewerSession(const ViewerConfig& config)
      : session_(config.session),
        domain_(config.domain,
                shipped_path("config/cyclonedds-loopback.xml", HAPSIM_BUILD_TREE_DDS_CONFIG),
                {config.interface, config.peers, config.security, config.security_label}),
        participant_(config.domain, config.session),
        info_in_(participant_),
        views_in_(participant_) {
    const auto give_up =
        std::chrono::steady_clock::now() + std::chrono::duration<double>(config.connect_timeout_s);
    std::optional<net::SceneInfoSample> info;
    while (!info && std::chrono::steady_clock::now() < give_up) {
      info = take_info();
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (!info) {
      throw Error("--connect", "no simulation host (hapsim serve … --session " + session_ +
                                   ") answered on DDS domain " + std::to_string(config.domain) +
                                   " within " + std::to_string(config.connect_timeout_s) + " s");
    }
    info_ = *info;
    // Built as the host built it (the device's stiffness limits are part of the world).
    setup_.emplace(
        net::build_served_scene(info_, DeviceChoice::external(), config.data_dir.string()));
    world_ = setup_->world.get();
    snapshot_ = make_world_snapshot(*world_);  // a rig's part too: view states carry it
    decoder_.emplace(*world_);
    view_ = std::make_unique<WorldScene>(*world_);
    // The scene's device is the one served (its limits built the world): its rating, not the
    // readout's default.
    readout_.rated_force_n = device_rated_force_n(*setup_->profile);
    readout_.bar_full_scale_n =
        force_display_scale_n(world_->description(), readout_.rated_force_n);
    WorldSceneOptions o = view_->options();
    o.force_full_scale_n = readout_.bar_full_scale_n;
    view_->set_options(o);
    view_->update(snapshot_);
    try {
      commands_.emplace(participant_, info_);
    } catch (const Error&) {
      // A secure session's viewer identity may not publish commands (its permissions): the
      // buttons then do nothing; an instructor's identity sends them.
      commands_.reset();
    }
    device_name_ = "simulation host '" + session_ + "'";
    title_ =
        std::filesystem::path(info_.scene_file).filename().string() + " — connected to " + session_;
    connected_at_ = std::chrono::steady_clock::now();
  }

  void update() override {
    if (auto info = take_info(); info && info->serve_id != info_.serve_id) {
      restarts_ += 1;
      restarted_other_scene_ = info->scene_hash != info_.scene_hash;
      info_.serve_id = info->serve_id;
      if (!restarted_other_scene_) {
        if (commands_) {
          commands_->retarget(*info);  // Pause and Reset go to the host that runs now
        }
      }
    }
    bool fresh = false;
    views_in_.take([&](const hapsim_msg_ViewState& m) {
      std::string why;
      if (decoder_->decode(m, info_.scene_hash, snapshot_, why)) {
        ++views_;
        fresh = true;
        host_driving_ = m.device_host_driving;
        host_paused_ = m.paused;
        last_view_ = std::chrono::steady_clock::now();
      } else {
        ++refused_;
        last_refusal_ = why;
      }
    });
    if (fresh) {
      view_->update(snapshot_);
      fill_world_readout(*world_, *view_, snapshot_, readout_);
    }
    const double age_s =
        views_ > 0
            ? std::chrono::duration<double>(std::chrono::steady_clock::now() - last_view_).count()
            : -1.0;
    // The data area says where the picture comes from and whether it is live.
    auto& lines = readout_.lines;
    lines.erase(std::remove_if(lines.begin(), lines.end(),
                               [](const auto& l) { return l.first.rfind("served", 0) == 0; }),
                lines.end());
    lines.emplace_back("served by", std::string(host_driving_ ? "serve, driven by a device host"
                                                              : "serve, driven by its script") +
                                        (host_paused_ ? " (paused)" : ""));
    lines.emplace_back(
        "served views",
        std::to_string(views_) +
            (refused_ > 0 ? ", " + std::to_string(refused_) + " refused (" + last_refusal_ + ")"
                          : std::string()) +
            (age_s < 0.0   ? ", none yet"
             : age_s > 0.5 ? ", none for " + std::to_string(static_cast<int>(age_s)) +
                                 " s: the host is silent"
                           : ""));
    if (restarts_ > 0) {
      lines.emplace_back("served restarts",
                         std::to_string(restarts_) +
                             (restarted_other_scene_ ? " (now another scene: reconnect)" : ""));
    }
  }

  RenderScene& render_scene() override { return view_->scene(); }
  Box3 bounds_world() const override { return view_->rest_bounds_world(); }
  const SessionReadout& readout() const override { return readout_; }
  HapticLoopStatus loop_status() const override {
    // No loop here: the figures are the views' (the host's loop reports its own).
    HapticLoopStatus s;
    s.running = views_ > 0;
    s.cycles = snapshot_.cycle;
    s.elapsed_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - connected_at_).count();
    s.rate_hz = s.elapsed_s > 0.0 ? static_cast<double>(views_) / s.elapsed_s : 0.0;
    return s;
  }
  bool runs_haptic_loop() const override { return false; }
  InteractiveDevice* mouse_device() override { return nullptr; }
  Vec3 probe_start_world() const override { return Vec3::Zero(); }
  const std::string& device_name() const override { return device_name_; }
  const std::vector<std::string>& warnings() const override { return setup_->scene.warnings; }
  const std::string& title() const override { return title_; }
  // Pause, Resume and Reset go to the simulation host as commands (net/command_sender.h): the
  // host pauses or resets the one world every viewer and the device host share.
  // The viewer calls set_paused with its own flag when it connects: nothing is sent then unless
  // it differs from what the host shows (a late viewer never resumes a paused host by joining).
  void set_paused(bool paused) override {
    if (paused == host_paused_) {
      return;
    }
    net::SessionCommand c;
    c.kind = paused ? net::SessionCommandKind::kPause : net::SessionCommandKind::kResume;
    commands_sent_ += commands_ && commands_->send(c) ? 1 : 0;
  }
  void reset() override {
    net::SessionCommand c;
    c.kind = net::SessionCommandKind::kReset;
    commands_sent_ += commands_ && commands_->send(c) ? 1 : 0;
  }
  void set_knee_overlays(bool influence_spheres, bool contact_vertices) override {
    WorldSceneOptions o = view_->options();
    o.show_influence_spheres = influence_spheres;
    o.show_contact_vertices = contact_vertices;
    view_->set_options(o);
  }
  void draw_controls() override {
    ImGui::TextWrapped(
        "Connected to session '%s' (scene hash %s). The simulation and the device run "
        "elsewhere: Pause, Resume and Reset are sent to the simulation host (%" PRIu64
        " sent), recording belongs to it.",
        session_.c_str(), hex(info_.scene_hash).c_str(), commands_sent_);
    draw_world_display_controls(*view_);
  }
  bool set_recording(const std::filesystem::path* /*path*/, std::string& error) override {
    error = "a connected viewer records nothing: record on the simulation host";
    return false;
  }
  bool recording() const override { return false; }

 private:
  std::optional<net::SceneInfoSample> take_info() { return net::take_scene_info(info_in_); }

  std::string session_;
  net::DdsDomain domain_;
  net::Participant participant_;
  net::LoanedReader<hapsim_msg_SceneInfo> info_in_;
  net::LoanedReader<hapsim_msg_ViewState> views_in_;
  net::SceneInfoSample info_;
  std::optional<RunSetup> setup_;
  std::optional<net::CommandSender> commands_;
  std::uint64_t commands_sent_ = 0;
  bool host_paused_ = false;
  World* world_ = nullptr;
  WorldSnapshot snapshot_;
  std::optional<net::ViewStateDecoder> decoder_;
  std::unique_ptr<WorldScene> view_;
  SessionReadout readout_;
  std::string device_name_;
  std::string title_;
  std::uint64_t views_ = 0;
  std::uint64_t refused_ = 0;
  std::string last_refusal_;
  bool host_driving_ = false;
  std::uint64_t restarts_ = 0;
  bool restarted_other_scene_ = false;
  std::chrono::steady_clock::time_point connected_at_;
  std::chrono::steady_clock::time_point last_view_;
};

}  // namespace

std::unique_ptr<ViewerSession> make_net_viewer_session(const ViewerConfig& config) {
  return std::make_unique<NetViewerSession>(config);
}

}  // namespace hapsim
