#include "hapsim/ui/viewer.h"

#include "hapsim/core/atomic_file.h"
#include "hapsim/core/error.h"
#include "hapsim/core/leak_check.h"
#include "hapsim/core/statistics.h"
#include "hapsim/device/interactive_device.h"
#include "hapsim/render/camera.h"
#include "hapsim/render/png_image.h"
#include "hapsim/render/renderer.h"
#include "hapsim/render/snapshot_writer.h"
#include "hapsim/render/user_colour.h"
#include "hapsim/runtime/ramp_warning.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/ui/force_graph.h"
#include "hapsim/ui/mouse_probe.h"
#include "hapsim/ui/net_viewer_session.h"
#include "hapsim/ui/panel_refresh.h"
#include "hapsim/ui/render_cpu_time.h"
#include "hapsim/ui/space_mouse_camera.h"
#include "hapsim/ui/sub_buffer_present.h"
#include "hapsim/ui/viewer_scenes.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>
#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

// glReadPixels and friends without a loader (glvnd's libOpenGL exports the core functions).
#define GL_GLEXT_PROTOTYPES
#include <GL/glcorearb.h>

namespace hapsim {
namespace {

constexpr float kControlWidth = 310.0f;
constexpr float kDataWidth = 340.0f;

std::string glfw_error_text;

void on_glfw_error(int code, const char* text) {
  glfw_error_text = "GLFW error " + std::to_string(code) + ": " + (text != nullptr ? text : "");
}

struct InputState {
  double wheel_steps = 0.0;
  /// What the events say about the panels (null while they are drawn every frame), and their
  /// widths in window coordinates (0 when hidden).
  PanelRefresh* panel_refresh = nullptr;
  double panel_left_px = 0.0;
  double panel_right_px = 0.0;
};

InputState* input_of(GLFWwindow* window) {
  return static_cast<InputState*>(glfwGetWindowUserPointer(window));
}

// An event at the pointer: over a panel (or just off one) the panels are due.
void note_pointer(GLFWwindow* window) {
  InputState* state = input_of(window);
  if (state == nullptr || state->panel_refresh == nullptr) {
    return;
  }
  double x = 0.0;
  double y = 0.0;
  glfwGetCursorPos(window, &x, &y);
  int win_w = 0;
  int win_h = 0;
  glfwGetWindowSize(window, &win_w, &win_h);
  state->panel_refresh->pointer_event(x < state->panel_left_px ||
                                      x >= static_cast<double>(win_w) - state->panel_right_px);
}

void note_other_input(GLFWwindow* window) {
  InputState* state = input_of(window);
  if (state != nullptr && state->panel_refresh != nullptr) {
    state->panel_refresh->other_event();
  }
}

void on_scroll(GLFWwindow* window, double /*x*/, double y) {
  note_pointer(window);
  InputState* state = input_of(window);
  if (state != nullptr && !ImGui::GetIO().WantCaptureMouse) {
    state->wheel_steps += y;
  }
}

// ImGui's GLFW backend (1.86) polls the pointer's position and chains to these others.
void on_cursor(GLFWwindow* window, double /*x*/, double /*y*/) {
  note_pointer(window);
}
void on_mouse_button(GLFWwindow* window, int /*button*/, int /*action*/, int /*mods*/) {
  note_pointer(window);
}
void on_key(GLFWwindow* window, int /*key*/, int /*scancode*/, int /*action*/, int /*mods*/) {
  note_other_input(window);
}
void on_char(GLFWwindow* window, unsigned int /*codepoint*/) {
  note_other_input(window);
}
void on_refresh(GLFWwindow* window) {
  note_other_input(window);  // exposed again: the window's pixels need the panels too
}

// Mesa's software rasterisers, where drawing the panels costs a quarter of a frame; on a GPU they
// cost next to nothing and presenting a part of the window would bypass vsync.
bool software_rasteriser() {
  const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const std::string_view r = renderer != nullptr ? renderer : "";
  return r.find("llvmpipe") != std::string_view::npos ||
         r.find("softpipe") != std::string_view::npos;
}

// `described`: the scene file's description (only its views are kept; left empty for a connected
// viewer, whose scene is the host's).
std::unique_ptr<ViewerSession> make_session(const ViewerConfig& config,
                                            SceneDescription* described = nullptr) {
  if (config.connect) {
    return make_net_viewer_session(config);
  }
  SceneLoadOptions load;
  load.data_dir = config.data_dir;
  // Only "sim" plays the scene's trajectory file (the mouse, sim:FILE and the 3D mouse do not).
  load.device_trajectory_played = config.device == "sim";
  const SceneDescription scene = load_scene(config.scene, load);
  if (described != nullptr) {
    described->file = scene.file;
    described->views = scene.views;
  }
  return make_viewer_session(config, scene);
}

std::vector<std::uint8_t> read_window(int width, int height) {
  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(width) * height * 4);
  std::vector<std::uint8_t> row(static_cast<std::size_t>(width) * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  // GL's rows run bottom-up; images top-down.
  for (int y = 0; y < height / 2; ++y) {
    std::uint8_t* a = rgba.data() + static_cast<std::size_t>(y) * width * 4;
    std::uint8_t* b = rgba.data() + static_cast<std::size_t>(height - 1 - y) * width * 4;
    std::copy(a, a + row.size(), row.begin());
    std::copy(b, b + row.size(), a);
    std::copy(row.begin(), row.end(), b);
  }
  return rgba;
}

struct FrameStats {
  std::size_t frames = 0;
  std::vector<double> frame_ms;
  double fps_recent = 0.0;
  double draw_ms_recent = 0.0;
  /// Frames that drew the panels too (the others drew only the 3D view: ui/panel_refresh.h).
  std::size_t whole_frames = 0;
  /// CPU time from the first frame on (render_cpu_time.h).
  RenderCpuTime cpu_start;
};

class Viewer {
 public:
  explicit Viewer(const ViewerOptions& options)
      : options_(options),
        config_(options.config),
        panel_refresh_(options.panel_refresh_hz > 0.0 ? 1.0 / options.panel_refresh_hz : 0.0) {
    glfwSetErrorCallback(on_glfw_error);
    if (glfwInit() == GLFW_FALSE) {
      throw Error("viewer", "cannot open a window (" + glfw_error_text +
                                "): no display? On a headless machine use `hapsim run SCENE "
                                "--snapshot FILE.png`, or run the viewer under xvfb-run");
    }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_DOUBLEBUFFER, GLFW_TRUE);
    // Multisampling costs ~2.6x per frame on Mesa's software rasteriser: off unless asked for.
    glfwWindowHint(GLFW_SAMPLES, std::max(0, options.msaa_samples));
    window_ = glfwCreateWindow(options.width_px, options.height_px, "hapsim", nullptr, nullptr);
    if (window_ == nullptr) {
      glfwTerminate();
      throw Error("viewer", "cannot create an OpenGL 3.3 core window (" + glfw_error_text + ")");
    }
    glfwMakeContextCurrent(window_);
    glfwSwapInterval(options.vsync ? 1 : 0);
    glfwSetWindowUserPointer(window_, &input_);
    glfwSetScrollCallback(window_, on_scroll);  // before ImGui, which chains to them
    glfwSetCursorPosCallback(window_, on_cursor);
    glfwSetMouseButtonCallback(window_, on_mouse_button);
    glfwSetKeyCallback(window_, on_key);
    glfwSetCharCallback(window_, on_char);
    glfwSetWindowRefreshCallback(window_, on_refresh);
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;
    ImGui::StyleColorsDark();
    ImGui_ImplGlfw_InitForOpenGL(window_, true);
    ImGui_ImplOpenGL3_Init("#version 330 core");
    panels_ = options.panels;
    stereo_ = options.stereo;
    renderer_ = std::make_unique<Renderer>();
    gl_version_ = renderer_->gl_version();
    keep_libraries_mapped_for_leak_check();  // Mesa's driver is loaded by now
    if (options.panel_refresh_hz > 0.0 && software_rasteriser()) {
      presenter_ = SubBufferPresenter::for_current_context();
    }
    if (presenter_) {
      input_.panel_refresh = &panel_refresh_;
    }
    scene_choices_ = options.scene_choices;
    if (!config_.connect && std::find(scene_choices_.begin(), scene_choices_.end(),
                                      config_.scene) == scene_choices_.end()) {
      scene_choices_.insert(scene_choices_.begin(), config_.scene);
    }
    rebuild(config_);
  }

  ~Viewer() {
    session_.reset();  // stops the haptic loop (zero force) before the window goes
    renderer_.reset();
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    glfwDestroyWindow(window_);
    glfwTerminate();
  }
  Viewer(const Viewer&) = delete;
  Viewer& operator=(const Viewer&) = delete;
  Viewer(Viewer&&) = delete;
  Viewer& operator=(Viewer&&) = delete;

  int run() {
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    auto last = start;
    auto fps_window_start = start;
    std::size_t fps_window_frames = 0;
    double draw_ms_sum = 0.0;
    bool first_written = false;
    std::vector<std::uint8_t> last_frame;
    int fb_w = 0;
    int fb_h = 0;
    stats_.cpu_start = render_cpu_time_now();
    while (glfwWindowShouldClose(window_) == GLFW_FALSE) {
      const auto now = Clock::now();
      const double dt_s = std::chrono::duration<double>(now - last).count();
      last = now;
      const double elapsed_s = std::chrono::duration<double>(now - start).count();
      if ((options_.duration_s > 0.0 && elapsed_s >= options_.duration_s) ||
          (options_.stop != nullptr && options_.stop->load(std::memory_order_relaxed))) {
        break;
      }
      glfwPollEvents();
      handle_input(dt_s);
      if (pending_rebuild_) {
        pending_rebuild_ = false;
        rebuild(pending_config_);
      }
      session_->update();
      const SessionReadout& r = session_->readout();
      forces_.push(r.bars);
      peak_deflection_m_ = std::max(peak_deflection_m_, r.max_deflection_m);

      int next_fb_w = 0;
      int next_fb_h = 0;
      glfwGetFramebufferSize(window_, &next_fb_w, &next_fb_h);
      if (next_fb_w != fb_w || next_fb_h != fb_h) {
        panel_refresh_.other_event();  // resized: the panels move
        fb_w = next_fb_w;
        fb_h = next_fb_h;
      }
      const auto d0 = Clock::now();
      const Viewport v = view_rect(fb_w, fb_h);
      const bool first_due =
          !first_written && !options_.first_screenshot.empty() && stats_.frames >= 3;
      const bool last_frame_due = options_.duration_s > 0.0 &&
                                  elapsed_s + 2.0 * std::max(dt_s, 0.001) >= options_.duration_s;
      const bool screenshot_due =
          !options_.screenshot.empty() && (last_frame_due || screenshot_requested_);
      // The panels too, or the 3D view alone over the panels' pixels of an earlier frame.
      input_.panel_left_px = control_width();
      input_.panel_right_px = data_width();
      const ImGuiIO& io = ImGui::GetIO();
      // ImGui settles its windows' layout over its first frames: those draw the panels too.
      const bool whole =
          !presenter_ || !panels_ || stats_.whole_frames < 3 || first_due || screenshot_due ||
          panel_refresh_.due(elapsed_s, io.WantCaptureMouse || io.WantCaptureKeyboard);
      if (whole) {
        // The whole back buffer, in the panels' colour: they are drawn without a background of
        // their own (ImGuiWindowFlags_NoBackground), since on a software rasteriser blending a
        // textured quad over 650×720 pixels cost ~5 ms of its CPU a frame; a clear costs next to
        // nothing.
        glViewport(0, 0, fb_w, fb_h);
        const ImVec4 panel = ImGui::GetStyle().Colors[ImGuiCol_WindowBg];
        glClearColor(panel.x, panel.y, panel.z, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
      }
      // The renderer clears its own viewport.
      draw_stereo(*renderer_, session_->render_scene(), camera_, stereo_, options_.eye_separation_m,
                  v.x, v.y, v.w, v.h);
      if (whole) {
        draw_panels();
        panel_refresh_.drawn(elapsed_s);
        ++stats_.whole_frames;
      }
      const double draw_ms = std::chrono::duration<double, std::milli>(Clock::now() - d0).count();
      draw_ms_sum += draw_ms;
      if (first_due) {
        write_png(options_.first_screenshot.string(), fb_w, fb_h, read_window(fb_w, fb_h));
        first_written = true;
      }
      if (screenshot_due) {
        last_frame = read_window(fb_w, fb_h);
        if (screenshot_requested_) {
          write_png(options_.screenshot.string(), fb_w, fb_h, last_frame);
          screenshot_requested_ = false;
        }
      }
      if (!presenter_) {
        glfwSwapBuffers(window_);
      } else if (whole) {
        presenter_->present(0, 0, fb_w, fb_h);
      } else {
        presenter_->present(v.x, v.y, v.w, v.h);  // never a swap: the back buffer stays ours
      }

      ++stats_.frames;
      if (stats_.frames > 1) {
        stats_.frame_ms.push_back(1e3 * dt_s);
      }
      ++fps_window_frames;
      const double window_s = std::chrono::duration<double>(now - fps_window_start).count();
      if (window_s >= 0.5) {
        stats_.fps_recent = static_cast<double>(fps_window_frames) / window_s;
        stats_.draw_ms_recent = draw_ms_sum / static_cast<double>(fps_window_frames);
        fps_window_frames = 0;
        draw_ms_sum = 0.0;
        fps_window_start = now;
      }
    }
    const double wall_s = std::chrono::duration<double>(Clock::now() - start).count();
    if (!options_.screenshot.empty()) {
      if (last_frame.empty() && fb_w > 0) {
        last_frame = read_window(fb_w, fb_h);
      }
      write_png(options_.screenshot.string(), fb_w, fb_h, last_frame);
    }
    return finish(wall_s);
  }

 private:
  struct Viewport {
    int x = 0;
    int y = 0;
    int w = 1;
    int h = 1;
  };

  [[nodiscard]] float control_width() const { return panels_ ? kControlWidth : 0.0f; }
  [[nodiscard]] float data_width() const { return panels_ ? kDataWidth : 0.0f; }

  Viewport view_rect(int fb_w, int fb_h) const {
    int win_w = 0;
    int win_h = 0;
    glfwGetWindowSize(window_, &win_w, &win_h);
    const double sx = win_w > 0 ? static_cast<double>(fb_w) / win_w : 1.0;
    Viewport v;
    v.x = static_cast<int>(static_cast<double>(control_width()) * sx);
    v.w = std::max(1, fb_w - v.x - static_cast<int>(static_cast<double>(data_width()) * sx));
    v.y = 0;
    v.h = std::max(1, fb_h);
    return v;
  }

  void rebuild(const ViewerConfig& config) {
    std::unique_ptr<ViewerSession> next;
    SceneDescription described;  // the scene file's named views (none for a connected viewer)
    session_.reset();            // one haptic loop (and one exclusive device) at a time
    try {
      next = make_session(config, &described);
      config_ = config;
      status_message_.clear();
    } catch (const std::exception& e) {
      if (!built_once_) {
        throw;  // nothing ran before: the start-up error is the whole story
      }
      status_message_ = e.what();
      spdlog::error("viewer: {}", status_message_);
      try {
        next = make_session(config_);  // back to what ran before
      } catch (const std::exception& again) {
        // Nothing can run (e.g. the scene file was broken while open): end with both reasons.
        throw Error(config_.scene.string(),
                    status_message_ + "; and again with the previous settings: " + again.what());
      }
    }
    session_ = std::move(next);
    session_->render_scene().style.level_of_detail = true;  // the window draws far meshes coarser
    // The start's --view/--camera, --room and --overlay apply to the first scene only; one chosen
    // later in the menu is framed as usual.
    std::optional<OrbitCamera> asked;
    if (!built_once_) {
      asked = chosen_camera(described, options_.view, options_.camera);
      session_->render_scene().room.visible = options_.room;
      session_->set_knee_overlays(options_.influence_overlay, options_.contact_vertices_overlay);
    }
    built_once_ = true;
    // The scene's warnings, through the log as mesh defects are: once each, however often the
    // session is rebuilt (the JSON summary lists them all).
    for (const std::string& warning : session_->warnings()) {
      if (std::find(warnings_.begin(), warnings_.end(), warning) == warnings_.end()) {
        spdlog::warn("{}", warning);
        warnings_.push_back(warning);
      }
    }
    session_->set_paused(paused_);
    pending_config_ = config_;
    glfwSetWindowTitle(window_, ("hapsim — " + session_->title()).c_str());
    int fb_w = 0;
    int fb_h = 0;
    glfwGetFramebufferSize(window_, &fb_w, &fb_h);
    const Viewport v = view_rect(fb_w, fb_h);
    camera_ =
        asked ? *asked
              : framed_camera(session_->bounds_world(), static_cast<double>(v.w) / v.h, 1.95, 0.3);
    probe_ = MouseProbe(session_->probe_start_world(), probe_options(session_->bounds_world()));
    forces_ = ForceGraph{};
  }

  static MouseProbeOptions probe_options(const Box3& bounds) {
    MouseProbeOptions o;
    const Vec3 margin = Vec3::Constant(0.5 * bounds.sizes().maxCoeff() + 0.1);
    o.workspace_world = Box3(bounds.min() - margin, bounds.max() + margin);
    return o;
  }

  void handle_input(double dt_s) {
    const ImGuiIO& io = ImGui::GetIO();
    double x = 0.0;
    double y = 0.0;
    glfwGetCursorPos(window_, &x, &y);
    const double dx = x - cursor_x_;
    const double dy = y - cursor_y_;
    cursor_x_ = x;
    cursor_y_ = y;
    int win_w = 0;
    int win_h = 0;
    glfwGetWindowSize(window_, &win_w, &win_h);
    const bool in_view =
        x >= static_cast<double>(control_width()) && x <= win_w - static_cast<double>(data_width());
    const bool left = glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
    const bool right = glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS;
    const bool middle = glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS;
    const bool shift = glfwGetKey(window_, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS ||
                       glfwGetKey(window_, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS;
    const bool ctrl = glfwGetKey(window_, GLFW_KEY_LEFT_CONTROL) == GLFW_PRESS ||
                      glfwGetKey(window_, GLFW_KEY_RIGHT_CONTROL) == GLFW_PRESS;
    // A drag belongs to the view when it started there, not over a panel.
    if (!(left || right || middle)) {
      drag_in_view_ = false;
    } else if (!was_pressed_) {
      drag_in_view_ = in_view && !io.WantCaptureMouse;
    }
    was_pressed_ = left || right || middle;
    if (drag_in_view_) {
      if (left) {
        probe_.drag(dx, dy, camera_, win_h);
      } else if (middle || (right && shift)) {
        camera_.pan(dx, dy, win_h);
      } else if (right) {
        camera_.rotate(dx, dy);
      }
    }
    if (input_.wheel_steps != 0.0) {
      if (ctrl) {
        camera_.zoom(input_.wheel_steps);
      } else {
        probe_.wheel(input_.wheel_steps, camera_);
      }
      input_.wheel_steps = 0.0;
    }
    if (!io.WantCaptureKeyboard) {
      std::array<bool, kMaxFingers> held{};
      for (int f = 0; f < kMaxFingers; ++f) {
        held[static_cast<std::size_t>(f)] = glfwGetKey(window_, GLFW_KEY_1 + f) == GLFW_PRESS;
      }
      probe_.update_fingers(held, dt_s);
      key_edge(GLFW_KEY_G, [this] { probe_.set_grasp_closed(!probe_.grasp_closed()); });
      key_edge(GLFW_KEY_SPACE, [this] {
        paused_ = !paused_;
        session_->set_paused(paused_);
      });
      key_edge(GLFW_KEY_R, [this] { session_->reset(); });
      key_edge(GLFW_KEY_F, [this] { frame_view(); });
      key_edge(GLFW_KEY_M, [this] {
        DisplayMode& m = session_->render_scene().style.display_mode;
        m = m == DisplayMode::kFaces   ? DisplayMode::kLines
            : m == DisplayMode::kLines ? DisplayMode::kPoints
                                       : DisplayMode::kFaces;
      });
      key_edge(GLFW_KEY_V, [this] {
        stereo_ = stereo_ == StereoMode::kOff          ? StereoMode::kSideBySide
                  : stereo_ == StereoMode::kSideBySide ? StereoMode::kAnaglyph
                                                       : StereoMode::kOff;
      });
      key_edge(GLFW_KEY_C, [this] { space_mouse_camera_ = !space_mouse_camera_; });
      key_edge(GLFW_KEY_TAB, [this] {
        panels_ = !panels_;
        frame_view();
      });
      key_edge(GLFW_KEY_ESCAPE, [this] { glfwSetWindowShouldClose(window_, GLFW_TRUE); });
    }
    if (InteractiveDevice* mouse = session_->mouse_device()) {
      mouse->set_input(probe_.input());
    }
    if (SpaceMouseSource* space_mouse = session_->space_mouse()) {
      space_mouse->set_drives_camera(space_mouse_camera_);
      if (space_mouse_camera_) {
        drive_camera(camera_, space_mouse->axes(), dt_s);
      }
    }
  }

  template <class F>
  void key_edge(int key, F&& action) {
    const bool down = glfwGetKey(window_, key) == GLFW_PRESS;
    bool& was = key_down_[static_cast<std::size_t>(key) % key_down_.size()];
    if (down && !was) {
      action();
    }
    was = down;
  }

  void frame_view() {
    int fb_w = 0;
    int fb_h = 0;
    glfwGetFramebufferSize(window_, &fb_w, &fb_h);
    const Viewport v = view_rect(fb_w, fb_h);
    camera_.frame(session_->bounds_world(), static_cast<double>(v.w) / v.h, 1.05);
  }

  void draw_panels() {
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    if (!panels_) {
      ImGui::Render();
      ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
      return;
    }
    int win_w = 0;
    int win_h = 0;
    glfwGetWindowSize(window_, &win_w, &win_h);
    const auto h = static_cast<float>(win_h);
    const auto w = static_cast<float>(win_w);
    const ImGuiWindowFlags fixed = ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize |
                                   ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoBackground;

    ImGui::SetNextWindowPos(ImVec2(0, 0));
    ImGui::SetNextWindowSize(ImVec2(kControlWidth, h));
    ImGui::Begin("Control", nullptr, fixed);
    draw_control_area();
    ImGui::End();

    ImGui::SetNextWindowPos(ImVec2(w - kDataWidth, 0));
    ImGui::SetNextWindowSize(ImVec2(kDataWidth, 0.48f * h));
    ImGui::Begin("Data", nullptr, fixed);
    draw_data_area();
    ImGui::End();

    ImGui::SetNextWindowPos(ImVec2(w - kDataWidth, 0.48f * h));
    ImGui::SetNextWindowSize(ImVec2(kDataWidth, 0.52f * h));
    ImGui::Begin("Forces", nullptr, fixed);
    forces_.draw(session_->readout().bar_full_scale_n);
    ImGui::End();

    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  }

  void draw_control_area() {
    if (ImGui::CollapsingHeader("Run", ImGuiTreeNodeFlags_DefaultOpen)) {
      // Scene, device, contact and deformation method: a new session when applied.
      ImGui::PushItemWidth(180.0f);
      const std::string current = pending_config_.scene.filename().string();
      if (ImGui::BeginCombo("scene", current.c_str())) {
        for (const auto& s : scene_choices_) {
          if (ImGui::Selectable(s.filename().string().c_str(), s == pending_config_.scene)) {
            pending_config_.scene = s;
          }
        }
        ImGui::EndCombo();
      }
      // A driver plugin the viewer started with (--device plugin:PATH.so) stays on offer.
      const std::string& started = options_.config.device;
      if (started.rfind("plugin:", 0) == 0) {
        combo("device", pending_config_.device, {"mouse", "sim", "spacemouse", started.c_str()});
      } else {
        combo("device", pending_config_.device, {"mouse", "sim", "spacemouse"});
      }
      combo("contact method", pending_config_.method, {"", "exact", "spheretree", "knee"});
      combo("deformation", pending_config_.deformation, {"deflection", "none"});
      ImGui::PopItemWidth();
      if (ImGui::Button("Apply (restart)")) {
        pending_rebuild_ = true;
      }
      ImGui::SameLine();
      if (ImGui::Button(paused_ ? "Resume" : "Pause")) {
        paused_ = !paused_;
        session_->set_paused(paused_);
      }
      ImGui::SameLine();
      if (ImGui::Button("Reset")) {
        session_->reset();
      }
      if (!session_->recording()) {
        if (ImGui::Button("Record")) {
          const std::filesystem::path path =
              "hapsim-view-" + std::to_string(std::time(nullptr)) + ".rec";
          std::string error;
          if (session_->set_recording(&path, error)) {
            recording_path_ = path.string();
          } else {
            status_message_ = error;
          }
        }
      } else if (ImGui::Button("Stop recording")) {
        std::string error;
        session_->set_recording(nullptr, error);
        status_message_ = "recorded " + recording_path_;
      }
      if (session_->recording()) {
        ImGui::SameLine();
        ImGui::TextColored(ImVec4(1, 0.3f, 0.3f, 1), "REC %s", recording_path_.c_str());
      }
      if (!status_message_.empty()) {
        ImGui::TextWrapped("%s", status_message_.c_str());
      }
      for (const std::string& warning : session_->warnings()) {
        ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.8f, 0.3f, 1.0f));
        ImGui::TextWrapped("warning: %s", warning.c_str());
        ImGui::PopStyleColor();
      }
    }
    if (ImGui::CollapsingHeader("Display", ImGuiTreeNodeFlags_DefaultOpen)) {
      RenderScene& scene = session_->render_scene();
      int mode = static_cast<int>(scene.style.display_mode);
      ImGui::RadioButton("points", &mode, static_cast<int>(DisplayMode::kPoints));
      ImGui::SameLine();
      ImGui::RadioButton("lines", &mode, static_cast<int>(DisplayMode::kLines));
      ImGui::SameLine();
      ImGui::RadioButton("faces", &mode, static_cast<int>(DisplayMode::kFaces));
      scene.style.display_mode = static_cast<DisplayMode>(mode);
      ImGui::Checkbox("level of detail", &scene.style.level_of_detail);
      ImGui::Checkbox("floor", &scene.floor.visible);
      ImGui::SameLine();
      ImGui::Checkbox("room", &scene.room.visible);
      int lights = static_cast<int>(scene.lighting.lights.size());
      if (ImGui::SliderInt("lights", &lights, 1, Lighting::kMaxLights)) {
        resize_lights(scene.lighting, lights);
      }
      if (ImGui::Button("Frame scene (F)")) {
        frame_view();
      }
      if (session_->space_mouse() != nullptr) {
        ImGui::Checkbox("3D mouse drives the camera (C)", &space_mouse_camera_);
      }
      session_->draw_controls();
    }
    if (ImGui::CollapsingHeader("Help")) {
      ImGui::TextWrapped(
          "Left-drag: move the probe in the view plane. Wheel: push it in / pull it out. "
          "Right-drag: rotate. Middle-drag or shift+right-drag: pan. Ctrl+wheel: zoom. "
          "1-5: curl fingers. G: grasp. Space: pause. R: reset. M: display mode. F: frame. "
          "C: the 3D mouse drives the camera (twist/tilt orbit, push pans, pull zooms) or the "
          "probe. Tab: hide/show panels. Esc: quit.");
    }
  }

  static void resize_lights(Lighting& lighting, int count) {
    const Lighting defaults;
    while (static_cast<int>(lighting.lights.size()) > count) {
      lighting.lights.pop_back();
    }
    while (static_cast<int>(lighting.lights.size()) < count) {
      const std::size_t i = lighting.lights.size();
      if (i < defaults.lights.size()) {
        lighting.lights.push_back(defaults.lights[i]);
      } else {
        // Extra rim lights from behind, dim.
        const double a = 2.0 * static_cast<double>(i);
        lighting.lights.push_back({Vec3(std::cos(a), std::sin(a), -0.6).normalized(),
                                   Vec3f(0.2f, 0.2f, 0.22f), LightFrame::kCamera});
      }
    }
  }

  static void combo(const char* label, std::string& value,
                    std::initializer_list<const char*> items) {
    const std::string shown = value.empty() ? "(scene's)" : value;
    if (ImGui::BeginCombo(label, shown.c_str())) {
      for (const char* item : items) {
        const std::string text = std::string(item).empty() ? "(scene's)" : item;
        if (ImGui::Selectable(text.c_str(), value == item)) {
          value = item;
        }
      }
      ImGui::EndCombo();
    }
  }

  // "users: trainee instructor", each in its colour (several users in one world only).
  static void draw_user_legend(const SessionReadout& r) {
    std::array<bool, 8> said{};
    bool first = true;
    for (const ToolReadout& t : r.tools) {
      const auto k = static_cast<std::size_t>(std::clamp(t.device, 0, 7));
      if (t.user.empty() || said[k]) {
        continue;
      }
      said[k] = true;
      if (first) {
        ImGui::TextUnformatted("users:");
        first = false;
      }
      ImGui::SameLine();
      const Vec3f c = user_colour(t.device);
      ImGui::TextColored(ImVec4(c.x(), c.y(), c.z(), 1.0f), "%s", t.user.c_str());
    }
  }

  void draw_data_area() {
    const SessionReadout& r = session_->readout();
    const HapticLoopStatus st = session_->loop_status();
    ImGui::Text("t = %.3f s   %s", r.time_s, paused_ ? "(paused)" : "");
    ImGui::TextWrapped("device: %s", session_->device_name().c_str());
    ImGui::Separator();
    ImGui::TextUnformatted("tool            x      y      z mm    F N");
    for (const ToolReadout& t : r.tools) {
      if (!t.user.empty()) {
        // Several users: each tool's line in its user's colour (as drawn), a legend below.
        const Vec3f c = user_colour(t.device);
        const ImVec4 colour(c.x(), c.y(), c.z(), 1.0f);
        if (!t.present) {
          ImGui::TextColored(colour, "%-12.12s (no device host)", t.name.c_str());
          continue;
        }
        ImGui::TextColored(colour, "%-12.12s %6.1f %6.1f %6.1f %6.2f", t.name.c_str(),
                           t.p_world.x() * 1e3, t.p_world.y() * 1e3, t.p_world.z() * 1e3,
                           t.force_n);
      } else {
        ImGui::Text("%-12.12s %6.1f %6.1f %6.1f %6.2f", t.name.c_str(), t.p_world.x() * 1e3,
                    t.p_world.y() * 1e3, t.p_world.z() * 1e3, t.force_n);
      }
      if ((t.proxy_world - t.p_world).norm() > 1e-4) {
        ImGui::Text("  proxy      %6.1f %6.1f %6.1f", t.proxy_world.x() * 1e3,
                    t.proxy_world.y() * 1e3, t.proxy_world.z() * 1e3);
      }
    }
    draw_user_legend(r);
    for (const auto& [label, value] : r.lines) {
      ImGui::TextWrapped("%s: %s", label.c_str(), value.c_str());
    }
    ImGui::Text("contacts %zu, deflection %.2f mm", r.contact_count, r.max_deflection_m * 1e3);
    ImGui::Separator();
    if (!session_->runs_haptic_loop()) {
      // The haptic loop runs on the device host; this viewer only receives the served views.
      ImGui::Text("served views %.1f Hz", st.rate_hz);
      ImGui::Text("graphics %.1f fps (draw %.1f ms)", stats_.fps_recent, stats_.draw_ms_recent);
      draw_triangle_line();
      return;
    }
    ImGui::Text("haptic %.1f Hz (%s)", st.rate_hz, st.realtime_priority ? "SCHED_FIFO" : "normal");
    ImGui::Text("step cost p50 %.1f us  p99 %.1f us", st.cycle_cost_us.p50, st.cycle_cost_us.p99);
    ImGui::Text("period jitter p99 %.1f us, missed %llu", st.period_jitter_us.p99,
                static_cast<unsigned long long>(st.missed_deadlines));
    if (st.stall_events > 0) {
      ImGui::TextColored(ImVec4(1, 0.5f, 0.2f, 1), "stalls ramped to zero: %llu",
                         static_cast<unsigned long long>(st.stall_events));
    }
    if (const std::string warning = late_ramp_warning(st.cycles, st.late_ramp_cycles);
        !warning.empty()) {
      ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.5f, 0.2f, 1));
      ImGui::TextWrapped("%s", warning.c_str());
      ImGui::PopStyleColor();
    }
    ImGui::Text("graphics %.1f fps (draw %.1f ms)", stats_.fps_recent, stats_.draw_ms_recent);
    draw_triangle_line();
  }

  // How much the levels of detail saved in the last frame.
  void draw_triangle_line() const {
    const RenderStats& r = renderer_->last_frame_stats();
    ImGui::Text("triangles %zu of %zu (%zu meshes coarser)", r.triangles_drawn, r.triangles_full,
                r.meshes_coarser);
  }

  int finish(double wall_s) {
    const HapticLoopStatus st = session_->loop_status();
    const std::string ramp_warning = late_ramp_warning(st.cycles, st.late_ramp_cycles);
    const double fps = wall_s > 0.0 ? static_cast<double>(stats_.frames) / wall_s : 0.0;
    std::vector<double> frame_ms = stats_.frame_ms;
    const double frame_p50 = nearest_rank_percentile(frame_ms, 0.5);
    const double frame_p99 = nearest_rank_percentile(frame_ms, 0.99);
    double peak = 0.0;
    for (const double p : forces_.peaks()) {
      peak = std::max(peak, p);
    }
    const bool over = peak > session_->readout().rated_force_n + 1e-9;
    const bool ok = !over && !forces_.saw_nonfinite();
    // CPU per frame, load-independent where fps is not (a build beside the viewer).
    const RenderCpuTime cpu_end = render_cpu_time_now();
    const double frames = static_cast<double>(std::max<std::size_t>(stats_.frames, 1));
    const double viewer_cpu_ms =
        1e3 * (cpu_end.viewer_thread_s - stats_.cpu_start.viewer_thread_s) / frames;
    const double raster_cpu_ms =
        1e3 * (cpu_end.rasteriser_s - stats_.cpu_start.rasteriser_s) / frames;
    if (!options_.quiet) {
      std::printf("viewer       %s, %s\n", session_->title().c_str(), gl_version_.c_str());
      std::printf("graphics     %zu frames in %.2f s: %.1f fps (frame p50 %.1f ms, p99 %.1f ms)\n",
                  stats_.frames, wall_s, fps, frame_p50, frame_p99);
      std::printf("cpu/frame    viewer thread %.1f ms, rasteriser threads %.1f ms\n", viewer_cpu_ms,
                  raster_cpu_ms);
      std::printf("triangles    %zu drawn of %zu in the last frame (levels of detail)\n",
                  renderer_->last_frame_stats().triangles_drawn,
                  renderer_->last_frame_stats().triangles_full);
      if (presenter_) {
        std::printf(
            "panels       drawn in %zu of %zu frames (at least %.3g a second; the others drew "
            "and presented the 3D view alone)\n",
            stats_.whole_frames, stats_.frames, options_.panel_refresh_hz);
      }
      if (session_->runs_haptic_loop()) {
        std::printf(
            "haptic       %.2f Hz (%s), period jitter p50 %.1f us, p99 %.1f us, max %.1f "
            "us; missed deadlines %llu; cycle cost p50 %.1f us, p99 %.1f us\n",
            st.rate_hz, st.realtime_priority ? "SCHED_FIFO" : "normal scheduling",
            st.period_jitter_us.p50, st.period_jitter_us.p99, st.period_jitter_us.max,
            static_cast<unsigned long long>(st.missed_deadlines), st.cycle_cost_us.p50,
            st.cycle_cost_us.p99);
        if (!ramp_warning.empty()) {
          std::printf("haptic       %s\n", ramp_warning.c_str());
        }
      } else {
        std::printf(
            "served       %.1f views/s from the simulation host (the haptic loop is the "
            "device host's)\n",
            st.rate_hz);
      }
      std::printf(
          "forces       peak shown %.3f N (device rating %.1f N); largest deflection "
          "%.2f mm\n",
          peak, session_->readout().rated_force_n, peak_deflection_m_ * 1e3);
      if (!options_.screenshot.empty()) {
        std::printf("screenshot   %s\n", options_.screenshot.string().c_str());
      }
    }
    if (!options_.json.empty()) {
      nlohmann::json j;
      j["scene"] = config_.scene.string();
      j["device"] = session_->device_name();
      j["renderer"] = gl_version_;
      j["frames"] = stats_.frames;
      j["wall_s"] = wall_s;
      j["fps"] = fps;
      j["frame_ms"] = {{"p50", frame_p50}, {"p99", frame_p99}};
      j["triangles_last_frame"] = {{"drawn", renderer_->last_frame_stats().triangles_drawn},
                                   {"full", renderer_->last_frame_stats().triangles_full}};
      j["cpu_ms_per_frame"] = {{"viewer_thread", viewer_cpu_ms},
                               {"rasteriser_threads", raster_cpu_ms}};
      j["window"] = {options_.width_px, options_.height_px};
      j["msaa_samples"] = options_.msaa_samples;
      j["panels"] = panels_;
      // Frames that drew the panels; the others drew the 3D view alone (ui/panel_refresh.h).
      j["partial_redraw"] = presenter_.has_value();
      j["panel_frames"] = presenter_ ? stats_.whole_frames : stats_.frames;
      j["haptic"] = {{"rate_hz", st.rate_hz},
                     {"cycles", st.cycles},
                     {"scheduling", st.realtime_priority ? "SCHED_FIFO" : "normal"},
                     {"period_jitter_us",
                      {{"p50", st.period_jitter_us.p50},
                       {"p99", st.period_jitter_us.p99},
                       {"max", st.period_jitter_us.max}}},
                     {"cycle_cost_us",
                      {{"p50", st.cycle_cost_us.p50},
                       {"p99", st.cycle_cost_us.p99},
                       {"max", st.cycle_cost_us.max}}},
                     {"missed_deadlines", st.missed_deadlines},
                     {"stall_events", st.stall_events},
                     {"ramp_cycles", st.ramp_cycles},
                     {"late_ramp_cycles", st.late_ramp_cycles},
                     {"late_ramp_share", late_ramp_share(st.cycles, st.late_ramp_cycles)}};
      if (!ramp_warning.empty()) {
        j["haptic"]["warning"] = ramp_warning;
      }
      j["peak_force_n"] = forces_.peaks();
      j["max_deflection_m"] = peak_deflection_m_;
      j["warnings"] = warnings_;
      j["ok"] = ok;
      write_file_atomically(options_.json, j.dump(2) + '\n');
    }
    return ok ? 0 : 1;
  }

  ViewerOptions options_;
  ViewerConfig config_;
  ViewerConfig pending_config_;
  bool pending_rebuild_ = false;
  GLFWwindow* window_ = nullptr;
  std::unique_ptr<Renderer> renderer_;
  std::string gl_version_;
  std::unique_ptr<ViewerSession> session_;
  std::vector<std::filesystem::path> scene_choices_;
  OrbitCamera camera_;
  MouseProbe probe_{Vec3::Zero()};
  ForceGraph forces_;
  InputState input_;
  /// Present without swapping, to redraw the 3D view alone (software rasteriser only).
  std::optional<SubBufferPresenter> presenter_;
  PanelRefresh panel_refresh_;
  FrameStats stats_;
  double cursor_x_ = 0.0;
  double cursor_y_ = 0.0;
  bool was_pressed_ = false;
  bool drag_in_view_ = false;
  bool paused_ = false;
  bool built_once_ = false;
  bool panels_ = true;
  /// The 3D mouse (--device spacemouse) turns the camera instead of moving the probe (C key).
  bool space_mouse_camera_ = false;
  StereoMode stereo_ = StereoMode::kOff;
  bool screenshot_requested_ = false;
  std::array<bool, 512> key_down_{};
  double peak_deflection_m_ = 0.0;
  std::string status_message_;
  /// Every warning printed so far (each once), for the JSON summary.
  std::vector<std::string> warnings_;
  std::string recording_path_;
};

}  // namespace

int run_viewer(const ViewerOptions& options) {
  Viewer viewer(options);
  return viewer.run();
}

}  // namespace hapsim
