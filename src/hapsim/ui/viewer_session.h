// What the viewer runs and shows (architecture.md#viewer): one scene on the real-time haptic loop
// with its device, a render scene kept up to date from the loop's snapshots, and the figures of the
// data area. A knee-type World and a teleoperation world each have one; the viewer rebuilds the
// session when the user picks another scene, device, contact method or deformation method.
#pragma once

#include "hapsim/core/device_io.h"
#include "hapsim/force/contact_material.h"
#include "hapsim/render/render_scene.h"
#include "hapsim/runtime/haptic_loop.h"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace hapsim {

class InteractiveDevice;
class SpaceMouseSource;

/// The choices that need a new session (everything else changes live).
struct ViewerConfig {
  std::filesystem::path scene;
  std::filesystem::path data_dir;
  /// "mouse" (the viewer's probe), "sim" (the scene's own script), "sim:FILE" (a trajectory),
  /// "spacemouse" (a 3D mouse through spacenavd) or "plugin:PATH.so" (a device driver plugin,
  /// device/plugin_device.h).
  std::string device = "mouse";
  /// plugin:PATH.so: the string the driver's open() gets.
  std::string driver_config;
  /// Contact method for every body: "" (the scene's), "exact", "spheretree" or "knee".
  std::string method;
  /// Deformation method: "deflection" (vertex deflection, eq. 1, the scene's deformable bodies)
  /// or "none" (every body rigid).
  std::string deformation = "deflection";
  /// Draw a world served by another process (hapsim serve) instead of running one: the scene
  /// comes from the simulation host of `session` on DDS `domain`.
  bool connect = false;
  std::string session = "default";
  int domain = 0;
  /// Not loopback: the interface and the unicast peers (net/dds_domain.h).
  std::string interface;
  std::vector<std::string> peers;
  /// A secure session (`--secure DIR`): the checked Cyclone <Security> fragment and what it is
  /// (net/security_config.h); empty: plain DDS.
  std::string security;
  std::string security_label;
  double connect_timeout_s = 20.0;

  bool operator==(const ViewerConfig&) const = default;
};

struct ToolReadout {
  std::string name;
  Vec3 p_world = Vec3::Zero();
  Vec3 proxy_world = Vec3::Zero();
  /// Force the device renders for this tool (its finger or its share of the tip force), N.
  double force_n = 0.0;
  int contacts = 0;
  /// Several users in one world: whose tool it is (the scene's device_host, "" for one user),
  /// the user's device index (its colour), and whether it is in the world (its host joined).
  std::string user;
  int device = 0;
  bool present = true;
};

/// The newest state, for the data area and the force graph.
struct SessionReadout {
  double time_s = 0.0;
  std::uint64_t cycle = 0;
  std::vector<ToolReadout> tools;
  /// Extra lines for the data area ("ball (mm)", "grasp force (N)" …).
  std::vector<std::pair<std::string, std::string>> lines;
  /// Bars of the force column graph: label and newtons (one per finger, or grasp and tip).
  std::vector<std::pair<std::string, double>> bars;
  /// The device's rated force, N: a force shown above it is a failure (the viewer's exit 1).
  double rated_force_n = 10.0;
  /// Full scale of the bars and plots: what the scene can push with, within the rating
  /// (force_scale.h), N; the graph grows past it if a force ever does.
  double bar_full_scale_n = 10.0;
  double max_deflection_m = 0.0;
  std::size_t contact_count = 0;
};

class ViewerSession {
 public:
  virtual ~ViewerSession() = default;

  /// Takes the newest snapshot from the haptic thread and updates the render scene.
  virtual void update() = 0;
  [[nodiscard]] virtual RenderScene& render_scene() = 0;
  [[nodiscard]] virtual Box3 bounds_world() const = 0;
  [[nodiscard]] virtual const SessionReadout& readout() const = 0;
  [[nodiscard]] virtual HapticLoopStatus loop_status() const = 0;
  /// False for a session that draws a world stepped elsewhere (view --connect): loop_status()
  /// then counts the views received (rate_hz: views per second), not haptic cycles.
  [[nodiscard]] virtual bool runs_haptic_loop() const { return true; }
  /// The probe's device when the config asked for the mouse (null otherwise).
  [[nodiscard]] virtual InteractiveDevice* mouse_device() = 0;
  /// The 3D mouse when the config asked for it (null otherwise): the viewer may take it to
  /// drive the camera instead of the probe.
  [[nodiscard]] virtual SpaceMouseSource* space_mouse() { return nullptr; }
  /// Where the probe starts (in front of the scene, as seen from the default camera).
  [[nodiscard]] virtual Vec3 probe_start_world() const = 0;
  [[nodiscard]] virtual const std::string& device_name() const = 0;
  /// What loading the scene and assembling the run warned about (SceneDescription::warnings).
  [[nodiscard]] virtual const std::vector<std::string>& warnings() const {
    static const std::vector<std::string> kNone;
    return kNone;
  }
  [[nodiscard]] virtual const std::string& title() const = 0;

  virtual void set_paused(bool paused) = 0;
  virtual void reset() = 0;
  /// ImGui widgets of what this session can change live (segments, materials, overlays).
  virtual void draw_controls() = 0;
  /// The knee method's overlays (the knee paper's Fig. 3, render/world_scene.h): each vertex
  /// group's sphere of influence, and the three vertices a touching tool's contact is tested
  /// against. The Display panel's boxes toggle them too.
  virtual void set_knee_overlays(bool influence_spheres, bool contact_vertices) = 0;
  /// Starts writing every haptic cycle to `path` (binary recording), or stops; false with a
  /// message in `error` when it cannot.
  virtual bool set_recording(const std::filesystem::path* path, std::string& error) = 0;
  [[nodiscard]] virtual bool recording() const = 0;
  /// New contact parameters for material `material` (the control area's stiffness and limits),
  /// applied by the haptic thread before its next step. False when this session has no such
  /// material or the change could not be queued.
  virtual bool set_material_contact(std::size_t /*material*/, const ContactMaterial& /*contact*/) {
    return false;
  }

 protected:
  ViewerSession() = default;
  ViewerSession(const ViewerSession&) = default;
  ViewerSession& operator=(const ViewerSession&) = default;
  ViewerSession(ViewerSession&&) = default;
  ViewerSession& operator=(ViewerSession&&) = default;
};

}  // namespace hapsim
