#include "hapsim/training/assessment_scorer.h"

#include "hapsim/core/error.h"
#include "hapsim/rig/rig_controller.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace hapsim {
namespace {

// Cycle i stands for the interval [i·dt, (i+1)·dt): a dwell of n cycles lasts n·dt and completes
// at the end of its last cycle. A dwell equal to its requirement counts (the tolerance absorbs
// the rounding of n·dt).
constexpr double kTimeToleranceS = 1e-9;

}  // namespace

std::size_t AssessmentResult::landmarks_found() const {
  return static_cast<std::size_t>(std::count_if(landmarks.begin(), landmarks.end(),
                                                [](const LandmarkResult& l) { return l.found; }));
}

AssessmentScorer::AssessmentScorer(const AssessmentDefinition& definition, const World& world,
                                   double dt_s, std::optional<Vec3> teleop_target_world)
    : definition_(definition), dt_s_(dt_s), teleop_target_world_(std::move(teleop_target_world)) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) {
    throw Error("assessment", "the cycle length must be > 0 s");
  }
  const WorldDescription& d = world.description();
  const TeleopRigDescription* rig = rig_description(d);
  rig_picks_ball_ = rig != nullptr && rig->ball_body != TeleopRigDescription::kNoBody;
  flat_count_ = world.flat_segment_count();
  body_first_flat_.resize(d.bodies.size(), 0);
  for (std::size_t b = 0; b < d.bodies.size(); ++b) {
    body_first_flat_[b] = d.bodies[b].segments.empty()
                              ? 0
                              : world.flat_segment(BodyIndex{b}, LocalSegment{0}).index();
  }
  // Flat segments by (body, segment) name, and the material of each.
  const auto segment_flat = [&](const std::string& body,
                                const std::string& segment) -> std::optional<std::size_t> {
    for (std::size_t b = 0; b < d.bodies.size(); ++b) {
      if (!body.empty() && d.bodies[b].name != body) {
        continue;
      }
      for (std::size_t s = 0; s < d.bodies[b].segments.size(); ++s) {
        if (d.bodies[b].segments[s].name == segment) {
          return world.flat_segment(BodyIndex{b}, LocalSegment{s}).index();
        }
      }
    }
    return std::nullopt;
  };
  const auto member_of = [&](const std::string& body, const std::string& segment,
                             const std::string& material, const std::string& what) {
    std::vector<bool> member(flat_count_, false);
    if (!material.empty()) {
      for (std::size_t b = 0; b < d.bodies.size(); ++b) {
        for (std::size_t s = 0; s < d.bodies[b].segments.size(); ++s) {
          const std::uint32_t m = d.bodies[b].segments[s].material;
          if (m < d.materials.size() && d.materials[m].name == material) {
            member[world.flat_segment(BodyIndex{b}, LocalSegment{s}).index()] = true;
          }
        }
      }
    } else if (const auto f = segment_flat(body, segment)) {
      member[*f] = true;
    } else {
      throw Error("assessment", what + ": the world has no segment '" + segment + "'");
    }
    return member;
  };

  columns_ = {"t_s", "total_force_n"};
  for (const AssessmentLandmark& l : definition_.landmarks) {
    const std::vector<bool> member = member_of(l.body, l.segment, "", "landmark " + l.name);
    LandmarkTrack track;
    for (std::size_t f = 0; f < flat_count_; ++f) {
      if (member[f]) {
        track.flat_segments.push_back(f);
      }
    }
    landmarks_.push_back(track);
  }
  for (const AssessmentLimit& l : definition_.limits) {
    LimitTrack track;
    track.flat_member = member_of(l.body, l.segment, l.material, "limit " + l.tissue());
    track.open.tissue = l.tissue();
    limits_.push_back(std::move(track));
    columns_.push_back(l.tissue());
    column_members_.push_back(limits_.back().flat_member);
  }
  for (std::size_t i = 0; i < definition_.landmarks.size(); ++i) {
    const std::string& name = definition_.landmarks[i].segment;
    if (std::find(columns_.begin(), columns_.end(), name) == columns_.end()) {
      columns_.push_back(name);
      std::vector<bool> member(flat_count_, false);
      for (const std::size_t f : landmarks_[i].flat_segments) {
        member[f] = true;
      }
      column_members_.push_back(std::move(member));
    }
  }
  scratch_segment_force_n_.resize(flat_count_);
  scratch_segment_point_.resize(flat_count_);
  scratch_segment_best_n_.resize(flat_count_);
}

std::size_t AssessmentScorer::flat(BodyIndex body, LocalSegment segment) const {
  if (!body.valid() || !segment.valid() || body.index() >= body_first_flat_.size()) {
    return flat_count_;
  }
  const std::size_t f = body_first_flat_[body.index()] + segment.index();
  return f < flat_count_ ? f : flat_count_;
}

void AssessmentScorer::add(const CycleRecord& record) {
  const double t0_s = static_cast<double>(cycles_) * dt_s_;
  const double t1_s = static_cast<double>(cycles_ + 1) * dt_s_;
  ++cycles_;

  // Force per flat segment, and where its strongest contact is.
  std::fill(scratch_segment_force_n_.begin(), scratch_segment_force_n_.end(), 0.0);
  std::fill(scratch_segment_best_n_.begin(), scratch_segment_best_n_.end(), -1.0);
  const int contact_count = std::clamp(record.contact_count, 0, kMaxCycleContacts);
  for (int c = 0; c < contact_count; ++c) {
    const WorldContact& contact = record.contacts[static_cast<std::size_t>(c)];
    const std::size_t f = flat(contact.body, contact.segment);
    if (f >= flat_count_ || !std::isfinite(contact.force_n)) {
      continue;
    }
    scratch_segment_force_n_[f] += contact.force_n;
    if (contact.force_n > scratch_segment_best_n_[f]) {
      scratch_segment_best_n_[f] = contact.force_n;
      scratch_segment_point_[f] = contact.point_world;
    }
  }

  // The tool(s): force and path (the tracker for a glove, the slave's tool for a rig).
  double total_n = 0.0;
  for (int i = 0; i < std::clamp(record.tool_count, 0, kMaxCycleTools); ++i) {
    total_n += record.tools[static_cast<std::size_t>(i)].force_world_n.norm();
  }
  if (std::isfinite(total_n) && (contact_count > 0 || total_n > 0.0)) {
    ++contact_cycles_;
    force_sum_n_ += total_n;
    peak_force_n_ = std::max(peak_force_n_, total_n);
  }
  std::optional<Vec3> path_point;
  if (record.has_teleop) {
    path_point = Vec3(record.teleop.slave_tool.translation());
  } else if (record.input.healthy) {
    path_point = record.input.p_world;
  }
  if (path_point && path_point->allFinite()) {
    if (last_path_point_) {
      path_length_m_ += (*path_point - *last_path_point_).norm();
    }
    last_path_point_ = path_point;
  }

  // Landmarks: the force on the segment (within the radius of the point, if one is given).
  for (std::size_t i = 0; i < landmarks_.size(); ++i) {
    const AssessmentLandmark& def = definition_.landmarks[i];
    LandmarkTrack& track = landmarks_[i];
    double force_n = 0.0;
    bool touching = false;
    double strongest_n = -1.0;
    Vec3 strongest_point = Vec3::Zero();
    for (int c = 0; c < contact_count; ++c) {
      const WorldContact& contact = record.contacts[static_cast<std::size_t>(c)];
      const std::size_t f = flat(contact.body, contact.segment);
      if (std::find(track.flat_segments.begin(), track.flat_segments.end(), f) ==
              track.flat_segments.end() ||
          !std::isfinite(contact.force_n)) {
        continue;
      }
      if (def.point_world && (contact.point_world - *def.point_world).norm() > def.radius_m) {
        continue;
      }
      touching = true;
      force_n += contact.force_n;
      if (contact.force_n > strongest_n) {
        strongest_n = contact.force_n;
        strongest_point = contact.point_world;
      }
    }
    if (touching) {
      if (track.contact_cycles == 0 || force_n > track.peak_force_n) {
        track.peak_force_n = force_n;
        track.peak_point_world = strongest_point;
      }
      ++track.contact_cycles;
      track.force_sum_n += force_n;
    }
    if (touching && force_n >= def.force_n) {
      ++track.run_cycles;
      track.best_run_cycles = std::max(track.best_run_cycles, track.run_cycles);
      if (!track.found &&
          static_cast<double>(track.run_cycles) * dt_s_ >= def.dwell_s - kTimeToleranceS) {
        track.found = true;
        track.found_at_s = t1_s;
        track.force_at_found_n = force_n;
      }
    } else {
      track.run_cycles = 0;
    }
  }

  // Force limits: a breach is a continuous spell above the limit.
  std::vector<double> tissue_force_n(limits_.size(), 0.0);
  for (std::size_t i = 0; i < limits_.size(); ++i) {
    LimitTrack& track = limits_[i];
    double force_n = 0.0;
    double best_n = -1.0;
    Vec3 best_point = Vec3::Zero();
    for (std::size_t f = 0; f < flat_count_; ++f) {
      if (track.flat_member[f] && scratch_segment_best_n_[f] >= 0.0) {
        force_n += scratch_segment_force_n_[f];
        if (scratch_segment_best_n_[f] > best_n) {
          best_n = scratch_segment_best_n_[f];
          best_point = scratch_segment_point_[f];
        }
      }
    }
    tissue_force_n[i] = force_n;
    const double limit_n = definition_.limits[i].max_force_n;
    if (force_n > limit_n) {
      if (!track.in_breach) {
        track.in_breach = true;
        track.open.start_s = t0_s;
        track.open.peak_force_n = -1.0;
        track.open_cycles = 0;
      }
      ++track.open_cycles;
      track.open.duration_s = static_cast<double>(track.open_cycles) * dt_s_;
      if (force_n > track.open.peak_force_n) {
        track.open.peak_force_n = force_n;
        track.open.excess_n = force_n - limit_n;
        track.open.peak_at_s = t0_s;
        track.open.point_world = best_point;
      }
    } else if (track.in_breach) {
      close_breach(i);
    }
  }

  // The force series: each 10 ms bin keeps each column's maximum.
  const auto bin = static_cast<std::size_t>(std::floor(t0_s / kAssessmentForceBinS + 1e-6));
  while (rows_.size() <= bin) {
    rows_.emplace_back(columns_.size(), 0.0);
    rows_.back()[0] = static_cast<double>(rows_.size() - 1) * kAssessmentForceBinS;
  }
  std::vector<double>& row = rows_[bin];
  if (std::isfinite(total_n)) {
    row[1] = std::max(row[1], total_n);
  }
  for (std::size_t c = 0; c < column_members_.size(); ++c) {
    double force_n = 0.0;
    for (std::size_t f = 0; f < flat_count_; ++f) {
      if (column_members_[c][f]) {
        force_n += scratch_segment_force_n_[f];
      }
    }
    row[2 + c] = std::max(row[2 + c], force_n);
  }

  // A teleoperation rig's pick and place.
  if (record.has_teleop && rig_picks_ball_) {
    has_teleop_ = true;
    const TeleopStepResult& t = record.teleop;
    if (t.held && !held_ && !grasp_at_s_) {
      grasp_at_s_ = t1_s;  // held at the end of this cycle (as the run summary times it)
    }
    if (!t.held && held_) {
      released_ = true;
      if (teleop_target_world_ &&
          (t.ball_p_world - *teleop_target_world_).norm() > kDropDistanceM) {
        ++drops_;
      }
    }
    held_ = t.held;
    peak_grasp_force_n_ = std::max(peak_grasp_force_n_, t.gripper.grasp_force_n());
    const bool colliding = t.slave_collisions > 0;
    if (colliding && !colliding_) {
      ++collisions_;
    }
    colliding_ = colliding;
    ball_finite_ = ball_finite_ && t.ball_p_world.allFinite();
    ball_world_ = t.ball_p_world;
  }
}

void AssessmentScorer::close_breach(std::size_t limit_index) {
  LimitTrack& track = limits_[limit_index];
  breaches_.push_back(track.open);
  track.in_breach = false;
}

AssessmentResult AssessmentScorer::finish() const {
  AssessmentResult r;
  r.kind = has_teleop_ ? "pick_and_place" : "palpation";
  r.duration_s = static_cast<double>(cycles_) * dt_s_;
  r.time_limit_s = definition_.time_limit_s;
  r.over_time = r.time_limit_s && r.duration_s > *r.time_limit_s + kTimeToleranceS;
  r.path_length_m = path_length_m_;
  r.mean_force_n = contact_cycles_ > 0 ? force_sum_n_ / static_cast<double>(contact_cycles_) : 0.0;
  r.peak_force_n = peak_force_n_;
  for (std::size_t i = 0; i < landmarks_.size(); ++i) {
    const AssessmentLandmark& def = definition_.landmarks[i];
    const LandmarkTrack& t = landmarks_[i];
    LandmarkResult l;
    l.name = def.name;
    l.segment = def.segment;
    l.point_world = def.point_world;
    l.radius_m = def.radius_m;
    l.required_force_n = def.force_n;
    l.required_dwell_s = def.dwell_s;
    l.found = t.found;
    l.found_at_s = t.found_at_s;
    l.force_at_found_n = t.force_at_found_n;
    l.dwell_s = static_cast<double>(t.best_run_cycles) * dt_s_;
    l.contact_s = static_cast<double>(t.contact_cycles) * dt_s_;
    l.touched = t.contact_cycles > 0;
    l.mean_force_n = l.touched ? t.force_sum_n / static_cast<double>(t.contact_cycles) : 0.0;
    l.peak_force_n = t.peak_force_n;
    l.peak_point_world = t.peak_point_world;
    r.landmarks.push_back(l);
  }
  r.breaches = breaches_;
  for (const LimitTrack& t : limits_) {
    if (t.in_breach) {
      r.breaches.push_back(t.open);  // still open at the end: it lasted until then
    }
  }
  std::stable_sort(
      r.breaches.begin(), r.breaches.end(),
      [](const BreachResult& a, const BreachResult& b) { return a.start_s < b.start_s; });
  for (const AssessmentLimit& def : definition_.limits) {
    LimitResult l;
    l.tissue = def.tissue();
    l.max_force_n = def.max_force_n;
    for (const BreachResult& b : r.breaches) {
      if (b.tissue != l.tissue) {
        continue;
      }
      ++l.breaches;
      l.breach_duration_s += b.duration_s;
      if (b.excess_n > l.worst_excess_n || l.breaches == 1) {
        l.worst_excess_n = b.excess_n;
        l.worst_at_s = b.peak_at_s;
        l.worst_point_world = b.point_world;
      }
    }
    r.limits.push_back(l);
  }
  if (has_teleop_) {
    TeleopAssessment t;
    t.time_to_grasp_s = grasp_at_s_;
    t.drops = drops_;
    if (teleop_target_world_ && ball_finite_) {
      t.placement_error_m = (ball_world_ - *teleop_target_world_).norm();
    }
    t.peak_grasp_force_n = peak_grasp_force_n_;
    t.collisions = collisions_;
    // As the session's summary judges it (TeleopSummary::placed): grasped, released, the ball
    // finite and within 5 mm of the target.
    t.placed = grasp_at_s_.has_value() && released_ && ball_finite_ &&
               (!teleop_target_world_ || (t.placement_error_m && *t.placement_error_m <= 0.005));
    r.teleop = t;
  }
  r.force_columns = columns_;
  r.force_rows = rows_;
  r.score = assessment_score(r);
  return r;
}

}  // namespace hapsim
