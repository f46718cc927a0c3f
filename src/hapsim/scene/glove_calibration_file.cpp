#include "hapsim/scene/glove_calibration_file.h"

#include "hapsim/core/error.h"
#include "hapsim/core/text_file.h"
#include "hapsim/scene/json_reader.h"
#include "hapsim/scene/json_text.h"

#include <cmath>
#include <numbers>

namespace hapsim {
namespace {

using Json = JsonReader::Json;

constexpr double kRadPerDeg = std::numbers::pi / 180.0;
// Both files are a few kilobytes; a megabyte is plenty.
constexpr std::size_t kMaxCalibrationFileBytes = std::size_t{1} << 20;

void check_format(const JsonReader& r, const Json& root, std::string_view format) {
  r.object(root, "", "a JSON object");
  const Json& f = r.required(root, "", "format");
  if (r.string(f, "/format", "the format") != format) {
    r.fail("/format", "expected \"" + std::string(format) + "\", got " + JsonReader::shown(f));
  }
  if (root.contains("layout") &&
      r.string(root["layout"], "/layout", "the sensor layout") != kGloveLayoutName) {
    r.fail("/layout", "expected \"" + std::string(kGloveLayoutName) + "\" (the only layout), got " +
                          JsonReader::shown(root["layout"]));
  }
}

// "j4" -> 4, else -1.
int joint_index(const std::string& name) {
  for (int j = 0; j < kGloveJoints; ++j) {
    if (name == glove_joint_name(j)) {
      return j;
    }
  }
  return -1;
}

}  // namespace

GloveProcedure parse_glove_procedure(std::string_view text, const std::filesystem::path& file) {
  const Json root = parse_json_text(text, file.string());
  const JsonReader r(file);
  check_format(r, root, kGloveProcedureFormat);
  r.allow_keys(root, "",
               {"$schema", "format", "layout", "description", "poses", "pivot", "tracker_to_hand"});
  GloveProcedure proc;
  const Json& poses = r.array(r.required(root, "", "poses"), "/poses", "the poses");
  if (poses.empty()) {
    r.fail("/poses", "expected at least one pose");
  }
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const std::string pp = JsonReader::at("/poses", i);
    const Json& p = r.object(poses[i], pp, "a pose {name, from_s, to_s, angles_deg}");
    r.allow_keys(p, pp, {"name", "description", "from_s", "to_s", "angles_deg"});
    GloveProcedurePose pose;
    pose.name = r.nonempty_string(r.required(p, pp, "name"), JsonReader::at(pp, "name"), "a name");
    for (const GloveProcedurePose& other : proc.poses) {
      if (other.name == pose.name) {
        r.fail(JsonReader::at(pp, "name"), "pose '" + pose.name + "' is listed twice");
      }
    }
    r.required(p, pp, "from_s");
    r.required(p, pp, "to_s");
    pose.from_s = r.number_in(p, pp, "from_s", 0.0, 0.0, 1e6, "seconds");
    pose.to_s = r.number_in(p, pp, "to_s", 0.0, 0.0, 1e6, "seconds");
    if (!(pose.to_s > pose.from_s)) {
      r.fail(JsonReader::at(pp, "to_s"), "expected a time after from_s");
    }
    // Angles by joint name; a joint not named is 0 (straight, unspread).
    const std::string ap = JsonReader::at(pp, "angles_deg");
    const Json& angles = r.object(r.required(p, pp, "angles_deg"), ap,
                                  "an object of joint angles in degrees, e.g. {\"j4\": 90}");
    for (auto it = angles.begin(); it != angles.end(); ++it) {
      const int j = joint_index(it.key());
      if (j < 0) {
        r.fail(JsonReader::at(ap, it.key()), "unknown joint '" + it.key() + "'; expected j0..j" +
                                                 std::to_string(kGloveJoints - 1));
      }
      pose.angles_rad[static_cast<std::size_t>(j)] =
          r.number_in(angles, ap, it.key().c_str(), 0.0, -180.0, 180.0, "degrees") * kRadPerDeg;
    }
    proc.poses.push_back(pose);
  }
  if (root.contains("pivot")) {
    const Json& p = r.object(root["pivot"], "/pivot", "the pivot window {from_s, to_s}");
    r.allow_keys(p, "/pivot", {"from_s", "to_s", "description"});
    r.required(p, "/pivot", "from_s");
    r.required(p, "/pivot", "to_s");
    proc.has_pivot = true;
    proc.pivot_from_s = r.number_in(p, "/pivot", "from_s", 0.0, 0.0, 1e6, "seconds");
    proc.pivot_to_s = r.number_in(p, "/pivot", "to_s", 0.0, 0.0, 1e6, "seconds");
    if (!(proc.pivot_to_s > proc.pivot_from_s)) {
      r.fail("/pivot/to_s", "expected a time after from_s");
    }
  }
  if (root.contains("tracker_to_hand")) {
    const Iso3 X = r.parse_pose(root["tracker_to_hand"], "/tracker_to_hand");
    if (proc.has_pivot && root["tracker_to_hand"].contains("position_m")) {
      r.fail("/tracker_to_hand/position_m",
             "the pivot fits the position: give either 'pivot' or a position, not both");
    }
    proc.p_tracker_hand = X.translation();
    proc.q_tracker_hand = Quat(X.linear());
  }
  return proc;
}

GloveProcedure load_glove_procedure(const std::filesystem::path& file) {
  return parse_glove_procedure(
      read_text_file(file, kMaxCalibrationFileBytes, "glove calibration procedure"), file);
}

Json glove_calibration_json(const GloveCalibration& c, const std::string& raw_file,
                            const std::string& procedure_file) {
  Json root = Json::object();
  root["format"] = kGloveCalibrationFormat;
  root["layout"] = kGloveLayoutName;
  root["model"] =
      "counts_s = offset_s + (theta_joint + coupling_s * theta_coupled_joint) / gain_s; angles "
      "= the inverse over all sensors (docs/glove-calibration.md)";
  Json sensors = Json::array();
  for (int s = 0; s < kGloveSensors; ++s) {
    const GloveSensorFit& f = c.sensors[static_cast<std::size_t>(s)];
    Json js;
    js["sensor"] = glove_sensor_name(s);
    js["name"] = glove_sensor_layout()[static_cast<std::size_t>(s)].name;
    js["joint"] = glove_joint_name(f.joint);
    js["coupled_joint"] = f.coupled_joint >= 0 ? Json(glove_joint_name(f.coupled_joint)) : Json();
    js["offset_counts"] = f.offset_counts;
    js["gain_deg_per_count"] = f.gain_rad_per_count / kRadPerDeg;
    js["coupling"] = f.coupling;
    js["range_counts"] = f.range_counts;
    sensors.push_back(js);
  }
  root["sensors"] = sensors;
  const Quat& q = c.q_tracker_hand;
  root["tracker_to_hand"] = {
      {"position_m", {c.p_tracker_hand.x(), c.p_tracker_hand.y(), c.p_tracker_hand.z()}},
      {"quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()}}};
  root["tracker_to_hand_fit"] = {{"method", c.palm_offset_fitted ? "pivot" : "given"},
                                 {"rms_m", c.pivot_rms_m},
                                 {"samples", c.pivot_samples}};
  Json residuals = Json::array();
  for (const GloveJointResidual& r : c.residuals) {
    residuals.push_back({{"joint", glove_joint_name(r.joint)},
                         {"sensor", glove_sensor_name(r.sensor)},
                         {"rms_deg", r.rms_deg},
                         {"max_deg", r.max_deg}});
  }
  root["residuals"] = residuals;
  root["held_samples"] = c.held_samples;
  root["source"] = {{"raw", raw_file}, {"procedure", procedure_file}};
  return root;
}

GloveCalibration parse_glove_calibration(std::string_view text, const std::filesystem::path& file) {
  const Json root = parse_json_text(text, file.string());
  const JsonReader r(file);
  check_format(r, root, kGloveCalibrationFormat);
  r.allow_keys(root, "",
               {"format", "layout", "model", "sensors", "tracker_to_hand", "tracker_to_hand_fit",
                "residuals", "held_samples", "source"});
  r.required(root, "", "layout");
  GloveCalibration c;
  const Json& sensors = r.array(r.required(root, "", "sensors"), "/sensors", "the sensors");
  if (sensors.size() != kGloveSensors) {
    r.fail("/sensors", "expected " + std::to_string(kGloveSensors) + " sensors (s0..s" +
                           std::to_string(kGloveSensors - 1) + "), got " +
                           std::to_string(sensors.size()));
  }
  for (int s = 0; s < kGloveSensors; ++s) {
    const std::string sp = JsonReader::at("/sensors", static_cast<std::size_t>(s));
    const Json& js = r.object(sensors[static_cast<std::size_t>(s)], sp, "a sensor's calibration");
    r.allow_keys(js, sp,
                 {"sensor", "name", "joint", "coupled_joint", "offset_counts", "gain_deg_per_count",
                  "coupling", "range_counts"});
    const GloveSensorSpec& spec = glove_sensor_layout()[static_cast<std::size_t>(s)];
    const auto expect_name = [&](const char* key, const std::string& want) {
      const Json& v = r.required(js, sp, key);
      if (!v.is_string() || v.get<std::string>() != want) {
        r.fail(JsonReader::at(sp, key), "expected \"" + want + "\" (layout " +
                                            std::string(kGloveLayoutName) + "), got " +
                                            JsonReader::shown(v));
      }
    };
    expect_name("sensor", glove_sensor_name(s));
    expect_name("joint", glove_joint_name(spec.joint));
    if (spec.coupled_joint >= 0) {
      expect_name("coupled_joint", glove_joint_name(spec.coupled_joint));
    }
    GloveSensorFit& f = c.sensors[static_cast<std::size_t>(s)];
    f.joint = spec.joint;
    f.coupled_joint = spec.coupled_joint;
    r.required(js, sp, "offset_counts");
    r.required(js, sp, "gain_deg_per_count");
    f.offset_counts = r.number_in(js, sp, "offset_counts", 0.0, -1e9, 1e9, "counts");
    const double gain_deg = r.number_in(js, sp, "gain_deg_per_count", 0.0, -1e6, 1e6, "deg/count");
    if (gain_deg == 0.0) {
      r.fail(JsonReader::at(sp, "gain_deg_per_count"), "expected a non-zero gain");
    }
    f.gain_rad_per_count = gain_deg * kRadPerDeg;
    f.coupling =
        spec.coupled_joint >= 0 ? r.number_in(js, sp, "coupling", 0.0, -100.0, 100.0, "") : 0.0;
    f.range_counts = r.number_in(js, sp, "range_counts", 0.0, 0.0, 1e9, "counts");
  }
  if (root.contains("tracker_to_hand")) {
    const Iso3 X = r.parse_pose(root["tracker_to_hand"], "/tracker_to_hand");
    c.p_tracker_hand = X.translation();
    c.q_tracker_hand = Quat(X.linear());
  }
  if (root.contains("tracker_to_hand_fit")) {
    const Json& fit = r.object(root["tracker_to_hand_fit"], "/tracker_to_hand_fit", "an object");
    c.palm_offset_fitted = fit.contains("method") && fit["method"] == "pivot";
    c.pivot_rms_m = r.number_in(fit, "/tracker_to_hand_fit", "rms_m", 0.0, 0.0, 1e3, "m");
    c.pivot_samples = static_cast<std::size_t>(
        r.number_in(fit, "/tracker_to_hand_fit", "samples", 0.0, 0.0, 1e12, "rows"));
  }
  if (root.contains("residuals")) {
    const Json& res = r.array(root["residuals"], "/residuals", "the residuals per joint");
    for (std::size_t i = 0; i < res.size(); ++i) {
      const std::string rp = JsonReader::at("/residuals", i);
      const Json& jr = r.object(res[i], rp, "a joint's residual");
      GloveJointResidual g;
      const int j = jr.contains("joint") && jr["joint"].is_string()
                        ? joint_index(jr["joint"].get<std::string>())
                        : -1;
      if (j < 0) {
        r.fail(JsonReader::at(rp, "joint"), "expected a joint j0..j14");
      }
      g.joint = j;
      // The sensor that reads it, from the layout (the file's "sensor" is for people).
      for (int k = 0; k < kGloveSensors; ++k) {
        if (glove_sensor_layout()[static_cast<std::size_t>(k)].joint == j) {
          g.sensor = k;
        }
      }
      g.rms_deg = r.number_in(jr, rp, "rms_deg", 0.0, 0.0, 1e6, "degrees");
      g.max_deg = r.number_in(jr, rp, "max_deg", 0.0, 0.0, 1e6, "degrees");
      c.residuals.push_back(g);
    }
  }
  finish_glove_calibration(c, file.string() + ":/sensors");
  return c;
}

GloveCalibration load_glove_calibration(const std::filesystem::path& file) {
  return parse_glove_calibration(
      read_text_file(file, kMaxCalibrationFileBytes, "glove calibration"), file);
}

Trajectory load_glove_trajectory(const std::filesystem::path& file,
                                 const GloveCalibration* calibration,
                                 const std::filesystem::path& calibration_file) {
  const Trajectory t = load_trajectory_csv(file);
  if (t.sensor_count == 0) {
    if (calibration != nullptr) {
      throw Error(file.string(), "has joint angles, not raw sensor columns s0..s" +
                                     std::to_string(kGloveSensors - 1) + ", so the calibration " +
                                     calibration_file.string() +
                                     " would be ignored; drop the device's \"calibration\" or "
                                     "give a raw trajectory");
    }
    return t;
  }
  if (calibration == nullptr) {
    throw Error(file.string(), "has raw sensor columns s0..s" + std::to_string(t.sensor_count - 1) +
                                   ", which need a glove calibration: add \"calibration\": "
                                   "\"USER.json\" to the glove device (hapsim calibrate glove)");
  }
  return calibrated_glove_trajectory(t, *calibration, file.string());
}

}  // namespace hapsim
