#include "hapsim/training/assessment_json.h"

#include <cstdio>

namespace hapsim {
namespace {

using Json = nlohmann::json;

Json point(const Vec3& p) {
  return Json::array({p.x(), p.y(), p.z()});
}

template <class T>
Json or_null(const std::optional<T>& v) {
  return v ? Json(*v) : Json(nullptr);
}

}  // namespace

Json assessment_json(const AssessmentResult& r, const AssessmentSource& source) {
  Json j;
  j["schema"] = "hapsim.assessment/1";
  j["recording"] = source.recording;
  j["scene"] = source.scene;
  j["scene_name"] = source.scene_name;
  j["kind"] = r.kind;
  j["duration_s"] = r.duration_s;
  j["time_limit_s"] = or_null(r.time_limit_s);
  j["over_time"] = r.over_time;
  j["path_length_m"] = r.path_length_m;
  j["mean_force_n"] = r.mean_force_n;
  j["peak_force_n"] = r.peak_force_n;
  j["landmarks"] = Json::array();
  for (const LandmarkResult& l : r.landmarks) {
    Json o;
    o["name"] = l.name;
    o["segment"] = l.segment;
    o["point_m"] = l.point_world ? point(*l.point_world) : Json(nullptr);
    o["radius_m"] = l.point_world ? Json(l.radius_m) : Json(nullptr);
    o["required_force_n"] = l.required_force_n;
    o["required_dwell_s"] = l.required_dwell_s;
    o["found"] = l.found;
    o["found_at_s"] = l.found ? Json(l.found_at_s) : Json(nullptr);
    o["force_at_found_n"] = l.found ? Json(l.force_at_found_n) : Json(nullptr);
    o["dwell_s"] = l.dwell_s;
    o["contact_s"] = l.contact_s;
    o["mean_force_n"] = l.touched ? Json(l.mean_force_n) : Json(nullptr);
    o["peak_force_n"] = l.touched ? Json(l.peak_force_n) : Json(nullptr);
    o["peak_point_m"] = l.touched ? point(l.peak_point_world) : Json(nullptr);
    j["landmarks"].push_back(o);
  }
  j["limits"] = Json::array();
  for (const LimitResult& l : r.limits) {
    Json o;
    o["tissue"] = l.tissue;
    o["max_force_n"] = l.max_force_n;
    o["breaches"] = l.breaches;
    o["breach_duration_s"] = l.breach_duration_s;
    o["worst_excess_n"] = l.breaches > 0 ? Json(l.worst_excess_n) : Json(nullptr);
    o["worst_at_s"] = l.breaches > 0 ? Json(l.worst_at_s) : Json(nullptr);
    o["worst_point_m"] = l.breaches > 0 ? point(l.worst_point_world) : Json(nullptr);
    j["limits"].push_back(o);
  }
  j["breaches"] = Json::array();
  for (const BreachResult& b : r.breaches) {
    j["breaches"].push_back({{"tissue", b.tissue},
                             {"start_s", b.start_s},
                             {"duration_s", b.duration_s},
                             {"peak_force_n", b.peak_force_n},
                             {"peak_at_s", b.peak_at_s},
                             {"excess_n", b.excess_n},
                             {"point_m", point(b.point_world)}});
  }
  if (r.teleop) {
    const TeleopAssessment& t = *r.teleop;
    j["teleop"] = {{"time_to_grasp_s", or_null(t.time_to_grasp_s)},
                   {"drops", t.drops},
                   {"placement_error_m", or_null(t.placement_error_m)},
                   {"peak_grasp_force_n", t.peak_grasp_force_n},
                   {"collisions", t.collisions},
                   {"placed", t.placed}};
  } else {
    j["teleop"] = nullptr;
  }
  Json terms = Json::object();
  for (const auto& [name, value] : r.score.terms) {
    terms[name] = value;
  }
  j["score"] = {{"value", r.score.value},
                {"max", r.score.max},
                {"formula", r.score.formula},
                {"terms", terms}};
  if (source.forces_file) {
    j["forces"] = {{"file", *source.forces_file}, {"columns", r.force_columns}};
  } else {
    j["forces"] = nullptr;
  }
  j["picture"] = or_null(source.picture_file);
  return j;
}

std::string assessment_forces_csv(const AssessmentResult& r) {
  std::string out;
  for (std::size_t c = 0; c < r.force_columns.size(); ++c) {
    out += (c == 0 ? "" : ",") + r.force_columns[c];
  }
  out += '\n';
  char number[32];
  for (const std::vector<double>& row : r.force_rows) {
    for (std::size_t c = 0; c < row.size(); ++c) {
      std::snprintf(number, sizeof number, "%.6g", row[c]);
      out += (c == 0 ? "" : ",");
      out += number;
    }
    out += '\n';
  }
  return out;
}

std::string format_assessment_summary(const AssessmentResult& r) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line,
                "assessment   %s, %.3f s%s, path %.3f m, force mean %.2f N peak %.2f N\n",
                r.kind.c_str(), r.duration_s, r.over_time ? " (OVER the time limit)" : "",
                r.path_length_m, r.mean_force_n, r.peak_force_n);
  out += line;
  if (!r.landmarks.empty()) {
    std::string found;
    std::string missed;
    for (const LandmarkResult& l : r.landmarks) {
      if (l.found) {
        std::snprintf(line, sizeof line, "%s%s (%.2f s, %.2f N)", found.empty() ? "" : ", ",
                      l.name.c_str(), l.found_at_s, l.force_at_found_n);
        found += line;
      } else {
        missed += (missed.empty() ? "" : ", ") + l.name;
      }
    }
    std::snprintf(line, sizeof line, "landmarks    %zu of %zu found: %s\n", r.landmarks_found(),
                  r.landmarks.size(), found.empty() ? "none" : found.c_str());
    out += line;
    if (!missed.empty()) {
      out += "missed       " + missed + "\n";
    }
  }
  if (!r.limits.empty()) {
    if (r.breaches.empty()) {
      out += "breaches     none (" + std::to_string(r.limits.size()) + " force limits)\n";
    }
    for (const LimitResult& l : r.limits) {
      if (l.breaches == 0) {
        continue;
      }
      std::snprintf(line, sizeof line,
                    "breaches     %s: %zu over %.1f N for %.3f s in all, worst +%.2f N at %.3f s\n",
                    l.tissue.c_str(), l.breaches, l.max_force_n, l.breach_duration_s,
                    l.worst_excess_n, l.worst_at_s);
      out += line;
    }
  }
  if (r.teleop) {
    const TeleopAssessment& t = *r.teleop;
    char grasp[32] = "never";
    if (t.time_to_grasp_s) {
      std::snprintf(grasp, sizeof grasp, "%.3f s", *t.time_to_grasp_s);
    }
    char error[32] = "-";
    if (t.placement_error_m) {
      std::snprintf(error, sizeof error, "%.2f mm", *t.placement_error_m * 1e3);
    }
    std::snprintf(line, sizeof line,
                  "pick&place   %s; grasp at %s, %zu drop(s), placement error %s, peak grasp "
                  "%.2f N, %zu slave collision(s)\n",
                  t.placed ? "placed" : "NOT placed", grasp, t.drops, error, t.peak_grasp_force_n,
                  t.collisions);
    out += line;
  }
  std::string terms;
  for (const auto& [name, value] : r.score.terms) {
    std::snprintf(line, sizeof line, "%s%s %+.1f", terms.empty() ? "" : ", ", name.c_str(), value);
    terms += line;
  }
  std::snprintf(line, sizeof line, "score        %.1f / %.0f (%s)\n", r.score.value, r.score.max,
                terms.c_str());
  out += line;
  return out;
}

}  // namespace hapsim
