// `hapsim view` for real: under Xvfb, the real X pointer (xdotool) drives the mouse probe into
// the knee; the viewer's own frame read-back must show the deformation (the 3D view changed
// where the probe pressed) and a non-zero force bar, and its JSON the force and the dent.
// Skips with a message where Xvfb or xdotool is missing. Also: no display is a clear error.
#include "hapsim_process.h"

#include "hapsim/render/image_compare.h"
#include "hapsim/render/png_image.h"
#include "hapsim/ui/force_graph.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace hapsim {
namespace {

bool have(const char* tool) {
  return std::system((std::string("command -v ") + tool + " > /dev/null 2>&1").c_str()) == 0;
}

// Pixels of the force bar's colour inside a rectangle of an RGBA image.
int count_colour(const RgbaImage& image, std::array<unsigned char, 4> rgba, int x0, int y0, int x1,
                 int y1) {
  int n = 0;
  for (int y = std::max(0, y0); y < std::min(image.height, y1); ++y) {
    for (int x = std::max(0, x0); x < std::min(image.width, x1); ++x) {
      const std::uint8_t* p = &image.rgba[(static_cast<std::size_t>(y) * image.width + x) * 4];
      n += std::abs(p[0] - rgba[0]) <= 2 && std::abs(p[1] - rgba[1]) <= 2 &&
                   std::abs(p[2] - rgba[2]) <= 2
               ? 1
               : 0;
    }
  }
  return n;
}

// The columns x0 .. x0 + width of an RGBA image, every row (a panel, or the 3D view between them).
std::vector<std::uint8_t> columns(const RgbaImage& image, int x0, int width) {
  std::vector<std::uint8_t> c;
  const auto row_bytes = static_cast<std::ptrdiff_t>(4) * width;
  for (int y = 0; y < image.height; ++y) {
    const auto* row = &image.rgba[(static_cast<std::size_t>(y) * image.width + x0) * 4];
    c.insert(c.end(), row, row + row_bytes);
  }
  return c;
}

// A viewer script of tests/apps run under a virtual display: `SCRIPT HAPSIM_BIN ARGS OUT`, which
// leaves the viewer's log and JSON in OUT.
struct ScriptedView {
  int status = -1;
  std::string log;
  std::optional<nlohmann::json> json;
};

ScriptedView run_view_script(const std::string& script, const std::string& args,
                             const std::filesystem::path& out) {
  const std::string cmd = std::string("xvfb-run -a -s '-screen 0 1280x720x24' bash ") +
                          HAPSIM_SOURCE_DIR + "/tests/apps/" + script + " " + HAPSIM_BIN_PATH +
                          " " + args + " " + out.string();
  ScriptedView v;
  v.status = std::system(cmd.c_str());
  std::ifstream log(out / "view.log");
  v.log.assign(std::istreambuf_iterator<char>(log), {});
  std::ifstream in(out / "view.json");
  if (in) {
    v.json = nlohmann::json::parse(in);
  }
  return v;
}

TEST(ViewCommand, MouseProbeUnderXvfbDentsTheKneeAndShowsTheForce) {
  if (!have("xvfb-run") || !have("xdotool")) {
    GTEST_SKIP() << "xvfb-run or xdotool missing (scripts/setup.sh installs both)";
  }
  const auto out = test::temp_path("viewer");
  const ScriptedView v = run_view_script(
      "viewer_smoke.sh", std::string(HAPSIM_SCENES_DIR) + "/knee_procedural.json", out);
  ASSERT_EQ(v.status, 0) << v.log;
  ASSERT_TRUE(v.json) << v.log;
  const nlohmann::json& j = *v.json;
  const std::string& log_text = v.log;
  EXPECT_TRUE(j["ok"].get<bool>());
  EXPECT_GT(j["frames"].get<int>(), 20);
  EXPECT_GT(j["peak_force_n"][0].get<double>(), 0.1) << "the probe never pressed: " << log_text;
  EXPECT_GT(j["max_deflection_m"].get<double>(), 0.001);
  EXPECT_GT(j["haptic"]["cycles"].get<long>(), 5000);

  const RgbaImage first = read_png((out / "first.png").string());
  const RgbaImage last = read_png((out / "last.png").string());
  ASSERT_EQ(first.width, 1280);
  ASSERT_EQ(last.height, 720);
  // The force bar (its own colour) stands in the force panel at the bottom right, while the probe
  // still presses. Only where the haptic loop kept its period: a build too slow for it (Debug
  // ASan: 540 Hz, 2 500 late cycles in 12 s) ramps the force to zero after each gap, so its last
  // frame shows 0 N while the probe touches (the peak above still shows the press).
  const double rate_hz = j["haptic"]["rate_hz"].get<double>();
  if (rate_hz >= 900.0) {
    EXPECT_GT(count_colour(last, ForceGraph::kBarColour, 940, 360, 1280, 720), 50);
  } else {
    std::printf(
        "not checked: the force bar in the last frame (the haptic loop ran at %.0f Hz: "
        "this build cannot keep real time)\n",
        rate_hz);
  }
  EXPECT_EQ(count_colour(first, ForceGraph::kBarColour, 940, 360, 1280, 720), 0);
  // The 3D view (between the panels) changed: the probe moved in and the skin dented.
  const ImageDiff d = compare_images(columns(first, 320, 600), columns(last, 320, 600), 600, 720);
  EXPECT_GT(d.differing_fraction, 0.002) << d.describe();
}

// Between panel frames the viewer draws and presents the 3D view alone (ui/panel_refresh.h), on a
// software rasteriser. What the X server shows (not the viewer's own read-back) must keep the
// panels and follow the scene: two grabs of the screen a second apart, the panels redrawn at most
// every 20 s, the palpation moving the fingertip. The 3D view moved; the control panel is drawn and
// unchanged.
TEST(ViewCommand, FramesWithoutThePanelsKeepThemOnTheWindowAndShowTheSceneMoving) {
#ifndef HAPSIM_X11_GRAB_PATH
  GTEST_SKIP() << "built without X11's headers (libx11-dev): no screen grab";
#else
  if (!have("xvfb-run") || !have("xdotool")) {
    GTEST_SKIP() << "xvfb-run or xdotool missing (scripts/setup.sh installs both)";
  }
  const auto out = test::temp_path("viewer_partial");
  const ScriptedView v = run_view_script(
      "viewer_partial_frames.sh",
      std::string(HAPSIM_X11_GRAB_PATH) + " " + HAPSIM_SCENES_DIR + "/knee_procedural.json", out);
  ASSERT_EQ(v.status, 0) << v.log;
  ASSERT_TRUE(v.json) << v.log;
  const nlohmann::json& j = *v.json;
  const std::string& log_text = v.log;
  if (!j["partial_redraw"].get<bool>()) {
    GTEST_SKIP() << "not a software rasteriser with GLX_MESA_copy_sub_buffer here: the viewer "
                    "draws its panels every frame ("
                 << j["renderer"].get<std::string>() << ")";
  }
  // Whatever the machine's speed (a Debug ASan build draws 2-3 frames a second): the panels were
  // drawn only in the frames that must draw them (ImGui's three settling frames, the first
  // screenshot, the Escape key's, at most one 20 s refresh), and other frames drew the 3D view
  // alone.
  EXPECT_LE(j["panel_frames"].get<int>(), 6) << log_text;
  EXPECT_GE(j["frames"].get<int>() - j["panel_frames"].get<int>(), 2) << log_text;

  const RgbaImage a = read_png((out / "grab1.png").string());
  const RgbaImage b = read_png((out / "grab2.png").string());
  ASSERT_EQ(a.width, 1280);
  ASSERT_EQ(b.height, 720);
  // The control panel (x 0-300) on the screen in both grabs: its background, ImGui's dark window
  // colour (0.06 grey, which the viewer clears the panels' area with), around widgets and text
  // (69 % of it when drawn: neither blank nor something else), and the same in both.
  const int background = count_colour(a, {15, 15, 15, 255}, 0, 0, 300, 720);
  EXPECT_GT(background, 300 * 720 / 2);
  EXPECT_LT(background, 300 * 720 * 9 / 10);
  const std::vector<std::uint8_t> control_a = columns(a, 0, 300);
  const ImageDiff panel = compare_images(control_a, columns(b, 0, 300), 300, 720);
  EXPECT_LT(panel.differing_fraction, 0.002) << panel.describe();
  // The 3D view (x 320-920) followed the fingertip between the grabs.
  const ImageDiff view = compare_images(columns(a, 320, 600), columns(b, 320, 600), 600, 720);
  EXPECT_GT(view.differing_fraction, 0.002) << view.describe();
#endif
}

// The viewer prints the scene's warnings once (through the log, as `hapsim run` does) and lists
// them in its JSON: here a trajectory 100 m above the knee.
TEST(ViewCommand, PrintsTheScenesWarningsOnceAndListsThemInItsJson) {
  if (!have("xvfb-run")) {
    GTEST_SKIP() << "xvfb-run missing (scripts/setup.sh installs it)";
  }
  const auto far = test::write_file("view_far.csv",
                                    "t,x,y,z,qw,qx,qy,qz\n0,0,0,100,1,0,0,0\n1,0,0,100,1,0,0,0\n");
  const auto json = test::temp_path("view_warnings.json");
  const auto log = test::temp_path("view_warnings.log");
  const std::string cmd =
      std::string("xvfb-run -a -s '-screen 0 1280x720x24' ") + HAPSIM_BIN_PATH + " view " +
      HAPSIM_SCENES_DIR + "/knee_procedural.json --device sim:" + far.string() +
      " --duration 2 --size 640x480 --json " + json.string() + " > " + log.string() + " 2>&1";
  const int status = std::system(cmd.c_str());
  std::ifstream log_in(log);
  const std::string output((std::istreambuf_iterator<char>(log_in)), {});
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << output;
  const std::string warning = far.string() + ": the trajectory never comes within reach";
  const std::size_t first = output.find(warning);
  ASSERT_NE(first, std::string::npos) << output;
  EXPECT_EQ(output.find(warning, first + 1), std::string::npos) << output;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j.at("warnings").size(), 1u);
  EXPECT_EQ(j["warnings"][0].get<std::string>().rfind(warning, 0), 0u) << j["warnings"];
}

// One picture of `view SCENE OPTIONS` with the panels hidden: the mouse probe is never moved, so
// the scene stands still and pictures taken with different cameras compare.
RgbaImage view_picture(const std::string& scene, const std::string& options,
                       const std::string& name) {
  const auto png = test::temp_path(name + ".png");
  const auto log = test::temp_path(name + ".log");
  const std::string cmd = std::string("xvfb-run -a -s '-screen 0 1280x720x24' ") + HAPSIM_BIN_PATH +
                          " view " + HAPSIM_SCENES_DIR + "/" + scene +
                          " --duration 1.5 --no-panels --size 640x360 -q " + options +
                          " --screenshot " + png.string() + " > " + log.string() + " 2>&1";
  const int status = std::system(cmd.c_str());
  std::ifstream in(log);
  const std::string output((std::istreambuf_iterator<char>(in)), {});
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << cmd << "\n" << output;
  return read_png(png.string());
}

double differing(const RgbaImage& a, const RgbaImage& b) {
  return compare_images(a.rgba, b.rgba, a.width, a.height).differing_fraction;
}

TEST(ViewCommand, StartsFromTheScenesNamedViewOrAGivenCameraWithTheRoomAndTheOverlays) {
  if (!have("xvfb-run")) {
    GTEST_SKIP() << "xvfb-run missing (scripts/setup.sh installs it)";
  }
  // knee_hand_procedural.json's view "front": eye (0, 0.45, 0.1), target (0, 0, 0), 45 degrees.
  const std::string scene = "knee_hand_procedural.json";
  const RgbaImage named = view_picture(scene, "--view front", "view_named");
  const RgbaImage given = view_picture(scene, "--camera 0,0.45,0.1,0,0,0,45", "view_given");
  const RgbaImage framed = view_picture(scene, "", "view_framed");
  const RgbaImage room = view_picture(scene, "--room", "view_room");
  ASSERT_EQ(named.width, 640);
  EXPECT_LT(differing(named, given), 0.01);  // the view is that camera
  EXPECT_GT(differing(named, framed), 0.1);  // and not the default framing
  // The room's walls (RenderRoom's colour, unlit, one wall darker) fill part of the picture
  // with --room and none without it.
  const auto walls = [](const RgbaImage& image) {
    return count_colour(image, {199, 194, 178, 255}, 0, 0, image.width, image.height) +
           count_colour(image, {169, 165, 152, 255}, 0, 0, image.width, image.height);
  };
  EXPECT_GT(walls(room), 640 * 360 / 10);
  EXPECT_EQ(walls(framed), 0);
  // The knee method's overlays from the start: every vertex group's sphere of influence, three
  // great circles each, over the segments (the picture is otherwise the named view's).
  const RgbaImage influence =
      view_picture(scene, "--view front --overlay influence", "view_influence");
  EXPECT_GT(differing(named, influence), 0.01);
}

TEST(ViewCommand, BadCameraOptionsAreOneLineBeforeAnyWindow) {
  const std::string knee = std::string(HAPSIM_SCENES_DIR) + "/knee_procedural.json";
  for (const auto& [options, says] : std::vector<std::pair<std::string, std::string>>{
           {"--duration nan", "--duration"},
           {"--camera 1,2", "--camera"},
           {"--view front --camera 0,0,1,0,0,0,40", "give one of them"},
       }) {
    const auto r = test::run_hapsim("view " + knee + " " + options);
    EXPECT_EQ(r.exit_code, 2) << options << ": " << r.output;
    EXPECT_NE(r.output.find(says), std::string::npos) << options << ": " << r.output;
  }
  const auto r = test::run_hapsim("view --connect --view front");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--connect takes the scene from the host"), std::string::npos)
      << r.output;
}

TEST(ViewCommand, AnUnknownViewNamesTheScenesViews) {
  if (!have("xvfb-run")) {
    GTEST_SKIP() << "xvfb-run missing (scripts/setup.sh installs it)";
  }
  const auto log = test::temp_path("view_unknown.log");
  const std::string cmd = std::string("xvfb-run -a -s '-screen 0 1280x720x24' ") + HAPSIM_BIN_PATH +
                          " view " + HAPSIM_SCENES_DIR +
                          "/knee_hand_procedural.json --view nope --duration 1 > " + log.string() +
                          " 2>&1";
  const int status = std::system(cmd.c_str());
  std::ifstream in(log);
  const std::string output((std::istreambuf_iterator<char>(in)), {});
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2) << output;
  EXPECT_NE(output.find("--view nope: the scene has the views fig6, front"), std::string::npos)
      << output;
}

TEST(ViewCommand, NoDisplayIsAClearError) {
  const std::string cmd = std::string("env -u DISPLAY -u WAYLAND_DISPLAY ") + HAPSIM_BIN_PATH +
                          " view " + HAPSIM_SCENES_DIR + "/knee_procedural.json > " +
                          test::temp_path("nodisplay.txt").string() + " 2>&1";
  const int status = std::system(cmd.c_str());
  std::ifstream in(test::temp_path("nodisplay.txt"));
  const std::string output((std::istreambuf_iterator<char>(in)), {});
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2) << output;
  EXPECT_NE(output.find("no display"), std::string::npos) << output;
  EXPECT_NE(output.find("--snapshot"), std::string::npos) << output;
}

TEST(ViewCommand, BadScenePathIsNamed) {
  const auto r = test::run_hapsim("view /nonexistent/scene.json");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("/nonexistent/scene.json"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace hapsim
