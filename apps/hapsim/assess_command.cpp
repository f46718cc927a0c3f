// `hapsim assess REC... [--scene FILE] [--json FILE] [--report DIR] [--summary]`: scores recorded
// sessions against their scene's "assessment" (docs/assessment.md). Each recording is replayed
// through the world (bit for bit: every contact, not only the 16 a frame keeps, and a rig's ball,
// grasp and collisions), the scorer fed every cycle; with --report, DIR gets assessment.json,
// forces.csv and picture.png (the end of the session, landmarks marked) and the HTML report of
// python/hapsim/assessment_report.py (the contract: docs/assessment.md, "Report").
// With --verify, every recording's signature (FILE.sig, written by a secure serve:
// net/recording_signature.h) is checked against the session's keys before anything is scored.
#include "checked_output.h"
#include "commands.h"
#include "json_output.h"
#include "shipped_files.h"
#include "snapshot_view.h"

#include "hapsim/core/error.h"
#include "hapsim/core/printable_text.h"
#include "hapsim/device/recording.h"
#include "hapsim/net/recording_signature.h"
#include "hapsim/render/assessment_markers.h"
#include "hapsim/render/force_scale.h"
#include "hapsim/render/snapshot_writer.h"
#include "hapsim/render/world_scene.h"
#include "hapsim/rig/rig_controller.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/training/assessment_json.h"
#include "hapsim/training/recording_assessment.h"

#include <spdlog/spdlog.h>

#include <sys/wait.h>

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace hapsim::app {
namespace {

namespace fs = std::filesystem;

struct AssessArgs {
  std::vector<std::string> recordings;
  std::string scene;
  std::string json_path;
  std::string report_dir;
  std::string data_dir;
  bool summary = false;
  bool verify = false;
  std::string secure_dir;  // --secure DIR or HAPSIM_SECURE_DIR: the keys --verify checks against
};

// Whether `path` (canonical) lies in `root` or a folder below it.
bool lies_under(const fs::path& path, const fs::path& root) {
  std::error_code ec;
  const fs::path canonical_root = fs::canonical(root, ec);
  if (ec) {
    return false;
  }
  const auto [root_end, path_end] =
      std::mismatch(canonical_root.begin(), canonical_root.end(), path.begin(), path.end());
  return root_end == canonical_root.end();
}

// The scene a recording was made on: --scene (the user's choice, opened like any path given on
// the command line), else the path its header gives (as given, from here; else resolved when it
// was recorded). The header is data anyone can write, so the scene it names is followed only to
// a regular .json file that lies, symbolic links resolved, below the recording's own folder or a
// scenes/ folder (the project's, or the one in the folder hapsim runs in): a crafted header
// cannot make assess open /etc/passwd or a key file and echo bits of it.
fs::path scene_of(const std::string& recording, const RecordingHeader& header,
                  const std::string& scene_option) {
  if (!scene_option.empty()) {
    return scene_option;
  }
  if (header.scene_path.empty() && header.scene_path_absolute.empty()) {
    throw CommandError(recording + ": the recording does not name its scene (recording version " +
                       std::to_string(header.version) +
                       ", or a session built in code): give --scene FILE");
  }
  std::error_code ec;
  const std::vector<fs::path> roots = {
      fs::absolute(recording, ec).parent_path(),
      HAPSIM_SCENES_DIR,
      fs::current_path(ec) / "scenes",
  };
  std::string refused;
  for (const std::string* named : {&header.scene_path, &header.scene_path_absolute}) {
    if (named->empty() || !fs::is_regular_file(*named, ec)) {
      continue;
    }
    const fs::path canonical = fs::canonical(*named, ec);
    if (!ec && canonical.extension() == ".json" &&
        std::any_of(roots.begin(), roots.end(),
                    [&](const fs::path& root) { return lies_under(canonical, root); })) {
      return *named;
    }
    refused = *named;
  }
  if (!refused.empty()) {
    throw CommandError(recording + ": its header names the scene '" + printable_text(refused) +
                       "', which is not a .json file below the recording's folder or a scenes/ "
                       "folder: not opened (give --scene FILE if it is the scene)");
  }
  const std::string& named =
      header.scene_path.empty() ? header.scene_path_absolute : header.scene_path;
  throw CommandError(recording + ": its scene '" + printable_text(named) + "' is not there (nor '" +
                     printable_text(header.scene_path_absolute) + "'): give --scene FILE");
}

// The end of the session, framed on the landmarks and breaches (with a margin), from the scene's
// usual direction; the landmarks and breaches marked.
void write_picture(const World& world, const RunSetup& setup, const AssessmentDefinition& def,
                   const AssessmentResult& result, const fs::path& path) {
  WorldSceneOptions o;
  o.force_full_scale_n = force_display_scale_n(
      world.description(), rig_state(world) != nullptr
                               ? rig_description(world.description())->gripper.max_force_n
                               : device_rated_force_n(*setup.profile));
  WorldScene drawn(world, o);
  constexpr int kWidth = 1280;
  constexpr int kHeight = 720;
  constexpr double kAspect = static_cast<double>(kWidth) / kHeight;
  SnapshotWriter writer(kWidth, kHeight);
  const double yaw = snapshot_yaw_rad(world);
  const double pitch = snapshot_pitch_rad(world);
  const Vec3 towards_eye =
      -framed_camera(drawn.rest_bounds_world(), kAspect, yaw, pitch).forward_world();
  drawn.update_from_world(world);
  RenderScene& scene = drawn.scene();
  const double marker_m = std::clamp(0.02 * drawn.rest_bounds_world().sizes().norm(), 0.004, 0.03);
  std::vector<Iso3> X_world_body;
  for (std::size_t b = 0; b < world.body_count(); ++b) {
    X_world_body.push_back(world.body_pose(b));
  }
  const std::vector<Vec3> markers =
      landmark_marker_points(world.description(), X_world_body, def, towards_eye);
  std::vector<bool> found;
  Box3 marked;
  for (std::size_t i = 0; i < result.landmarks.size(); ++i) {
    found.push_back(result.landmarks[i].found);
    marked.extend(markers.at(i));
  }
  std::vector<Vec3> breach_points;
  for (const BreachResult& b : result.breaches) {
    breach_points.push_back(b.point_world);
    marked.extend(b.point_world);
  }
  add_assessment_markers(scene, def, markers, found, breach_points, marker_m);
  // A rig's task spans the whole scene; landmarks are framed with a margin of a twentieth of the
  // scene's size.
  Box3 framed = drawn.rest_bounds_world();
  if (!marked.isEmpty() && rig_state(world) == nullptr) {
    const double margin = 0.05 * drawn.rest_bounds_world().sizes().norm();
    framed = Box3(marked.min() - Vec3::Constant(margin), marked.max() + Vec3::Constant(margin));
  }
  writer.write_png(scene, framed_camera(framed, kAspect, yaw, pitch), path.string());
}

void write_text_file(const fs::path& path, const std::string& text) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) {
    throw CommandError("--report " + path.string() + ": cannot open for writing");
  }
  std::fwrite(text.data(), 1, text.size(), f);
  close_checked(f, "--report", path.string());
}

// Runs the report script with `arguments`; one line and exit 1 when it is missing or fails.
bool run_report_script(const std::vector<std::string>& arguments) {
  const std::string script = HAPSIM_ASSESSMENT_REPORT_SCRIPT;
  std::error_code ec;
  if (script.empty() || !fs::is_regular_file(script, ec)) {
    std::fprintf(stderr, "hapsim: the report script %s is not there: no HTML report written\n",
                 script.empty() ? "(not configured)" : script.c_str());
    return false;
  }
  std::string command = "python3 '" + script + "'";
  for (const std::string& a : arguments) {
    std::string quoted;
    for (const char c : a) {
      quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    }
    command += " '" + quoted + "'";
  }
  command += " >/dev/null";  // it prints the page's path, which hapsim says itself
  std::fflush(stdout);
  const int status = std::system(command.c_str());
  if (status != 0) {
    std::fprintf(stderr, "hapsim: the report script %s failed (exit status %d)\n", script.c_str(),
                 WIFEXITED(status) ? WEXITSTATUS(status) : status);
    return false;
  }
  return true;
}

struct Assessed {
  nlohmann::json json;
  AssessmentResult result;
};

// Assesses one recording; writes DIR's files when `report_dir` is given.
Assessed assess_one(const std::string& recording, const AssessArgs& args,
                    const std::optional<fs::path>& report_dir) {
  RecordingHeader header;
  try {
    header = RecordingReader(recording).header();
  } catch (const Error& e) {
    throw CommandError(std::string(e.what()));
  }
  const fs::path scene_file = scene_of(recording, header, args.scene);
  SceneLoadOptions load_options;
  if (!args.data_dir.empty()) {
    load_options.data_dir = args.data_dir;
  }
  SceneDescription scene = load_scene(scene_file, load_options);
  if (!scene.has_assessment) {
    throw CommandError(scene_file.string() +
                       ": the scene has no \"assessment\" (its landmarks and limits: "
                       "docs/assessment.md)");
  }
  const AssessmentDefinition definition = scene.assessment;
  const std::string scene_name = scene.description.empty()
                                     ? scene_file.stem().string()
                                     : scene.description.substr(0, scene.description.find(':'));
  RecordingAssessment assessed = [&] {
    try {
      return assess_recording(recording, std::move(scene));
    } catch (const Error& e) {
      if (std::string(e.where()) == recording) {
        throw CommandError(std::string(e.what()) +
                           " (the scene: " + printable_text(scene_file.string(), 4096) + ")");
      }
      throw;
    }
  }();
  if (!assessed.replay_difference.empty()) {
    spdlog::warn(
        "{}: the replay differs from the recording at {}; the assessment is of the "
        "replay",
        recording, assessed.replay_difference);
  }
  Assessed out;
  out.result = assessed.result;
  const World& world = *assessed.setup.world;
  std::printf("recording    %s (%zu frames) on %s\n", recording.c_str(), assessed.frames,
              scene_file.string().c_str());
  std::fputs(format_assessment_summary(out.result).c_str(), stdout);
  AssessmentSource source{recording, scene_file.string(), scene_name, std::nullopt, std::nullopt};
  if (report_dir) {
    source.forces_file = "forces.csv";
    write_text_file(*report_dir / "forces.csv", assessment_forces_csv(out.result));
    try {
      write_picture(world, assessed.setup, definition, out.result, *report_dir / "picture.png");
      source.picture_file = "picture.png";
    } catch (const Error& e) {
      // No display library or context: the report goes without the picture, and says so.
      spdlog::warn("picture: {}", e.what());
    }
  }
  out.json = assessment_json(out.result, source);
  if (report_dir) {
    write_json_file("--report", (*report_dir / "assessment.json").string(), out.json);
  }
  return out;
}

fs::path make_folder(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    throw CommandError("--report " + dir.string() + ": cannot create the folder (" + ec.message() +
                       ")");
  }
  return dir;
}

// --verify: each recording's signature, before anything is scored. A refused recording is one
// line naming it and why; false when any was refused.
bool verify_signatures(const AssessArgs& args) {
  if (args.secure_dir.empty()) {
    throw CommandError(
        "--verify: give the session's key directory with --secure DIR (or HAPSIM_SECURE_DIR)");
  }
  std::error_code ec;
  if (!fs::is_directory(args.secure_dir, ec)) {
    throw CommandError("--secure " + args.secure_dir + ": no such key directory");
  }
  const net::SecurityKeyDir keys(args.secure_dir);
  // The directory's own files once, not once per recording.
  (void)keys.session();
  (void)net::read_text_file(keys.identity_ca());
  (void)net::read_text_file(keys.crl());
  bool all = true;
  for (const std::string& recording : args.recordings) {
    try {
      const net::RecordingStatement s = net::verify_recording_signature(recording, keys);
      std::printf(
          "verified     %s: signed by serve identity '%s' of session '%s' at %s; a device "
          "host drove %" PRIu64 " of its %" PRIu64 " cycles\n",
          printable_text(recording).c_str(), printable_text(s.identity, 64).c_str(),
          printable_text(s.session, 64).c_str(), printable_text(s.signed_at, 40).c_str(),
          s.device_host_cycles, s.cycles);
    } catch (const Error& e) {
      std::fflush(stdout);
      std::fprintf(stderr, "hapsim: refused: %s\n", e.what());
      all = false;
    }
  }
  std::fflush(stdout);
  return all;
}

void assess(const AssessArgs& args) {
  JsonOutput json_out(args.json_path);
  if (args.verify && !verify_signatures(args)) {
    json_out.write_failure("a recording's signature did not verify");
    exit_status() = 2;
    return;
  }
  if (args.recordings.size() > 1 && !args.summary) {
    throw CommandError("several recordings: give --summary (and --report DIR) to assess a series");
  }
  if (args.summary && args.report_dir.empty()) {
    throw CommandError("--summary: give --report DIR (each session's report goes into it)");
  }
  if (args.summary && !args.json_path.empty() && args.recordings.size() > 1) {
    throw CommandError(
        "--json: one recording only (a series writes DIR/session-NN/assessment.json)");
  }
  if (!args.summary) {
    const std::optional<fs::path> dir =
        args.report_dir.empty() ? std::nullopt : std::optional(make_folder(args.report_dir));
    const Assessed a = assess_one(args.recordings.front(), args, dir);
    if (json_out) {
      json_out.write(a.json);
    }
    if (dir) {
      std::printf("wrote        %s{assessment.json,forces.csv%s}\n", (*dir / "").c_str(),
                  a.json["picture"].is_null() ? "" : ",picture.png");
      if (!run_report_script({"report", dir->string()})) {
        exit_status() = 1;
        return;
      }
      std::printf("report       %s\n", (*dir / "index.html").c_str());
    }
    return;
  }
  const fs::path root = make_folder(args.report_dir);
  std::vector<std::string> summary_arguments = {"summary", root.string()};
  bool reports = true;  // the script ran for every session so far
  for (std::size_t i = 0; i < args.recordings.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "session-%02zu", i + 1);
    const fs::path dir = make_folder(root / name);
    (void)assess_one(args.recordings[i], args, dir);
    // Every session is assessed even when the script is missing or fails (said once).
    reports = reports && run_report_script({"report", dir.string()});
    summary_arguments.push_back((dir / "assessment.json").string());
  }
  if (!reports || !run_report_script(summary_arguments)) {
    exit_status() = 1;
    return;
  }
  std::printf("report       %s (%zu sessions)\n", (root / "index.html").c_str(),
              args.recordings.size());
}

}  // namespace

void add_assess_command(CLI::App& app) {
  auto args = std::make_shared<AssessArgs>();
  CLI::App* cmd = app.add_subcommand(
      "assess",
      "Score recorded sessions against their scene's assessment: landmarks found, force-limit "
      "breaches, time, path, a score (docs/assessment.md)");
  cmd->add_option("recordings", args->recordings,
                  "Recording(s) (hapsim run --record, the viewer's record button)")
      ->required();
  cmd->add_option("--scene", args->scene,
                  "The scene the recording was made on (default: the one its header names)");
  cmd->add_option("--json", args->json_path, "Write the assessment as JSON to FILE");
  cmd->add_option("--report", args->report_dir,
                  "Write assessment.json, forces.csv, picture.png and the HTML report into DIR");
  cmd->add_flag("--summary", args->summary,
                "Several recordings as a series: DIR/session-NN/ each, and a learning curve");
  cmd->add_option("--data", args->data_dir, "Real-data folder for scenes that use one");
  cmd->add_flag("--verify", args->verify,
                "Score only recordings signed by a secure serve of the session (FILE.sig, "
                "hapsim serve --secure DIR --record FILE): refuse, before scoring, an unsigned, "
                "altered or cut recording or one signed by a revoked or non-serve identity");
  cmd->add_option("--secure", args->secure_dir,
                  "With --verify: the session's key directory (hapsim keys init; its "
                  "identity_ca.pem, crl.pem and session)")
      ->envname("HAPSIM_SECURE_DIR");
  cmd->callback([args] { assess(*args); });
}

}  // namespace hapsim::app
