// The scorer on synthetic cycles whose answers are counted by hand: a dwell exactly at its
// threshold counts and one cycle short does not; a breach lasts as many milliseconds as cycles
// were over the limit; a landmark's point and radius include a contact 9 mm away and exclude one
// 11 mm away; a material's limit sums its segments; the force series keeps each 10 ms bin's peak;
// the score follows docs/assessment.md's formula.
#include "hapsim/training/assessment_scorer.h"

#include "hapsim/core/error.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/training/assessment_json.h"

#include <gtest/gtest.h>

#include <memory>

namespace hapsim {
namespace {

constexpr double kDt = 0.001;

// Three static boxes: "a" and "b" of material "soft", "c" of "hard" (one segment each, named
// after the body).
std::unique_ptr<World> three_boxes() {
  const char* text = R"({
    "format": "hapsim-scene/1",
    "materials": { "soft": { "response": "penalty", "stiffness_n_per_m": 300 },
                   "hard": { "response": "penalty", "stiffness_n_per_m": 900 } },
    "bodies": [
      { "name": "a", "geometry": { "box": { "half_extents_m": [0.01, 0.01, 0.01] } },
        "materials": "soft" },
      { "name": "b", "pose": { "position_m": [0.1, 0, 0] },
        "geometry": { "box": { "half_extents_m": [0.01, 0.01, 0.01] } }, "materials": "soft" },
      { "name": "c", "pose": { "position_m": [0.2, 0, 0] },
        "geometry": { "box": { "half_extents_m": [0.01, 0.01, 0.01] } }, "materials": "hard" }
    ],
    "tools": [ { "name": "tip", "radius_m": 0.005 } ],
    "device": { "profile": "touch",
                "palpation": { "targets": [ { "body": "a", "segment": "a", "from": [0, 0, 1] } ] } }
  })";
  SceneDescription scene = parse_scene(text, "three_boxes.json");
  return std::make_unique<World>(scene.world);
}

// One cycle with the given contacts (body index, force, point), each on the body's one segment.
struct Touch {
  int body;
  double force_n;
  Vec3 point = Vec3::Zero();
};
CycleRecord cycle(std::initializer_list<Touch> touches) {
  CycleRecord r;
  r.tool_count = 1;
  double total = 0.0;
  for (const Touch& t : touches) {
    WorldContact& c = r.contacts[static_cast<std::size_t>(r.contact_count++)];
    c.tool = ToolIndex{0};
    c.body = BodyIndex{t.body};
    c.segment = LocalSegment{0};
    c.point_world = t.point;
    c.force_n = t.force_n;
    total += t.force_n;
  }
  r.tools[0].force_world_n = Vec3(0, 0, total);
  r.tools[0].contact_count = r.contact_count;
  return r;
}

AssessmentLandmark landmark(const std::string& name, const std::string& body, double force_n,
                            double dwell_s) {
  AssessmentLandmark l;
  l.name = name;
  l.body = body;
  l.segment = body;
  l.force_n = force_n;
  l.dwell_s = dwell_s;
  return l;
}

TEST(AssessmentScorer, ADwellExactlyAtItsThresholdCountsAndOneCycleShortDoesNot) {
  const auto world = three_boxes();
  AssessmentDefinition def;
  def.landmarks = {landmark("A", "a", 2.0, 0.3), landmark("B", "b", 2.0, 0.3)};
  AssessmentScorer scorer(def, *world, kDt);
  for (int i = 0; i < 100; ++i) {
    scorer.add(cycle({}));
  }
  // A: 300 cycles at exactly the force. B: 299 cycles, a break, 299 cycles.
  for (int i = 0; i < 299; ++i) {
    scorer.add(cycle({{0, 2.0}, {1, 2.5}}));
  }
  EXPECT_FALSE(scorer.landmark_found(0));
  scorer.add(cycle({{0, 2.0}, {1, 1.99}}));
  EXPECT_TRUE(scorer.landmark_found(0));
  for (int i = 0; i < 299; ++i) {
    scorer.add(cycle({{1, 3.0}}));
  }
  scorer.add(cycle({}));
  const AssessmentResult r = scorer.finish();
  ASSERT_EQ(r.landmarks.size(), 2u);
  const LandmarkResult& a = r.landmarks[0];
  EXPECT_TRUE(a.found);
  // Cycles 100..399 at the force: the dwell completes at the end of cycle 399, t = 0.400 s.
  EXPECT_NEAR(a.found_at_s, 0.400, 1e-12);
  EXPECT_DOUBLE_EQ(a.force_at_found_n, 2.0);
  EXPECT_NEAR(a.dwell_s, 0.300, 1e-12);
  EXPECT_NEAR(a.contact_s, 0.300, 1e-12);
  EXPECT_DOUBLE_EQ(a.mean_force_n, 2.0);
  const LandmarkResult& b = r.landmarks[1];
  EXPECT_FALSE(b.found);
  EXPECT_NEAR(b.dwell_s, 0.299, 1e-12);
  EXPECT_NEAR(b.contact_s, 0.599, 1e-12);
  EXPECT_DOUBLE_EQ(b.peak_force_n, 3.0);
  EXPECT_EQ(r.landmarks_found(), 1u);
  EXPECT_NEAR(r.duration_s, 0.700, 1e-12);  // 100 + 300 + 299 + 1 cycles
}

TEST(AssessmentScorer, ABreachLastsAsManyMillisecondsAsCyclesOverTheLimit) {
  const auto world = three_boxes();
  AssessmentDefinition def;
  AssessmentLimit limit;
  limit.body = "a";
  limit.segment = "a";
  limit.max_force_n = 5.0;
  def.limits = {limit};
  AssessmentScorer scorer(def, *world, kDt);
  for (int i = 0; i < 1000; ++i) {
    double f = 0.0;
    if (i >= 100 && i < 350) {
      f = i == 200 ? 7.5 : 6.0;  // 250 cycles over, the peak at cycle 200
    } else if (i >= 600 && i < 612) {
      f = 5.5;  // 12 cycles over
    } else if (i >= 700 && i < 800) {
      f = 5.0;  // at the limit: not over it
    }
    scorer.add(cycle({{0, f, Vec3(0.001 * i, 0.0, 0.01)}}));
  }
  const AssessmentResult r = scorer.finish();
  ASSERT_EQ(r.breaches.size(), 2u);
  EXPECT_EQ(r.breaches[0].tissue, "a");
  EXPECT_NEAR(r.breaches[0].start_s, 0.100, 1e-12);
  EXPECT_NEAR(r.breaches[0].duration_s, 0.250, 1e-12);
  EXPECT_DOUBLE_EQ(r.breaches[0].peak_force_n, 7.5);
  EXPECT_DOUBLE_EQ(r.breaches[0].excess_n, 2.5);
  EXPECT_NEAR(r.breaches[0].peak_at_s, 0.200, 1e-12);
  EXPECT_TRUE(r.breaches[0].point_world.isApprox(Vec3(0.2, 0.0, 0.01)));
  EXPECT_NEAR(r.breaches[1].start_s, 0.600, 1e-12);
  EXPECT_NEAR(r.breaches[1].duration_s, 0.012, 1e-12);
  ASSERT_EQ(r.limits.size(), 1u);
  EXPECT_EQ(r.limits[0].breaches, 2u);
  EXPECT_NEAR(r.limits[0].breach_duration_s, 0.262, 1e-12);
  EXPECT_DOUBLE_EQ(r.limits[0].worst_excess_n, 2.5);
  EXPECT_NEAR(r.limits[0].worst_at_s, 0.200, 1e-12);
}

TEST(AssessmentScorer, ABreachStillOpenAtTheEndLastsUntilThen) {
  const auto world = three_boxes();
  AssessmentDefinition def;
  AssessmentLimit limit;
  limit.material = "hard";
  limit.max_force_n = 1.0;
  def.limits = {limit};
  AssessmentScorer scorer(def, *world, kDt);
  for (int i = 0; i < 50; ++i) {
    scorer.add(cycle({{2, i >= 20 ? 2.0 : 0.5}}));
  }
  const AssessmentResult r = scorer.finish();
  ASSERT_EQ(r.breaches.size(), 1u);
  EXPECT_EQ(r.breaches[0].tissue, "hard");
  EXPECT_NEAR(r.breaches[0].start_s, 0.020, 1e-12);
  EXPECT_NEAR(r.breaches[0].duration_s, 0.030, 1e-12);
}

TEST(AssessmentScorer, AMaterialLimitSumsTheForceOnEverySegmentOfIt) {
  const auto world = three_boxes();
  AssessmentDefinition def;
  AssessmentLimit limit;
  limit.material = "soft";
  limit.max_force_n = 3.0;
  def.limits = {limit};
  AssessmentScorer scorer(def, *world, kDt);
  scorer.add(cycle({{0, 2.0}, {1, 0.5}, {2, 9.0}}));  // soft: 2.5 N, under
  scorer.add(cycle({{0, 2.0}, {1, 1.5}}));            // soft: 3.5 N, over
  scorer.add(cycle({}));
  const AssessmentResult r = scorer.finish();
  ASSERT_EQ(r.breaches.size(), 1u);
  EXPECT_NEAR(r.breaches[0].start_s, 0.001, 1e-12);
  EXPECT_DOUBLE_EQ(r.breaches[0].peak_force_n, 3.5);
}

TEST(AssessmentScorer, ALandmarksPointCountsOnlyContactsWithinItsRadius) {
  const auto world = three_boxes();
  AssessmentDefinition def;
  AssessmentLandmark near = landmark("near", "a", 1.0, 0.010);
  near.point_world = Vec3(0.0, 0.0, 0.01);
  near.radius_m = 0.010;
  AssessmentLandmark far = near;
  far.name = "far";
  far.point_world = Vec3(0.0, 0.0, -0.01);
  def.landmarks = {near, far};
  AssessmentScorer scorer(def, *world, kDt);
  // One contact 9 mm from "near"'s point (inside its 10 mm), one 11 mm from "far"'s (outside).
  for (int i = 0; i < 20; ++i) {
    scorer.add(cycle({{0, 1.5, Vec3(0.009, 0.0, 0.01)}, {0, 4.0, Vec3(0.0, 0.011, -0.01)}}));
  }
  const AssessmentResult r = scorer.finish();
  EXPECT_TRUE(r.landmarks[0].found);
  EXPECT_DOUBLE_EQ(r.landmarks[0].peak_force_n, 1.5);  // the other contact is 20 mm away
  EXPECT_FALSE(r.landmarks[1].found);
  EXPECT_FALSE(r.landmarks[1].touched);
}

TEST(AssessmentScorer, TheForceSeriesKeepsEachTenMillisecondBinsPeak) {
  const auto world = three_boxes();
  AssessmentDefinition def;
  def.landmarks = {landmark("B", "b", 1.0, 0.1)};
  AssessmentScorer scorer(def, *world, kDt);
  for (int i = 0; i < 25; ++i) {
    scorer.add(cycle({{1, i == 13 ? 4.0 : 1.0}}));
  }
  const AssessmentResult r = scorer.finish();
  ASSERT_EQ(r.force_columns, (std::vector<std::string>{"t_s", "total_force_n", "b"}));
  ASSERT_EQ(r.force_rows.size(), 3u);
  EXPECT_NEAR(r.force_rows[1][0], 0.010, 1e-12);
  EXPECT_DOUBLE_EQ(r.force_rows[0][2], 1.0);
  EXPECT_DOUBLE_EQ(r.force_rows[1][2], 4.0);
  EXPECT_DOUBLE_EQ(r.force_rows[1][1], 4.0);
  const std::string csv = assessment_forces_csv(r);
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "t_s,total_force_n,b");
  EXPECT_NE(csv.find("\n0.01,4,4\n"), std::string::npos) << csv;
}

TEST(AssessmentScorer, TheScoreFollowsTheDocumentedFormula) {
  const auto world = three_boxes();
  AssessmentDefinition def;
  def.landmarks = {landmark("A", "a", 1.0, 0.0), landmark("B", "b", 1.0, 0.0),
                   landmark("C", "c", 1.0, 0.0), landmark("never", "c", 100.0, 0.0)};
  AssessmentLimit limit;
  limit.body = "a";
  limit.segment = "a";
  limit.max_force_n = 4.0;
  def.limits = {limit};
  def.time_limit_s = 1.0;
  AssessmentScorer scorer(def, *world, kDt);
  // 2 of 4 landmarks (A, B); one breach of A: 250 ms at 6 N (excess 2 N over 4 N); 3.5 s long.
  for (int i = 0; i < 3500; ++i) {
    if (i < 250) {
      scorer.add(cycle({{0, 6.0}}));
    } else if (i < 260) {
      scorer.add(cycle({{1, 2.0}}));
    } else {
      scorer.add(cycle({}));
    }
  }
  const AssessmentResult r = scorer.finish();
  // landmarks 100·2/4 = 50; breaches −(5 + 10·0.25·(1 + 2/4)) = −8.75; time −2·2.5 = −5.
  ASSERT_EQ(r.score.terms.size(), 3u);
  EXPECT_EQ(r.score.terms[0].first, "landmarks");
  EXPECT_NEAR(r.score.terms[0].second, 50.0, 1e-9);
  EXPECT_NEAR(r.score.terms[1].second, -8.75, 1e-9);
  EXPECT_NEAR(r.score.terms[2].second, -5.0, 1e-9);
  EXPECT_NEAR(r.score.value, 36.25, 1e-9);
  EXPECT_TRUE(r.over_time);
  // The JSON carries the terms and the formula's text.
  const nlohmann::json j = assessment_json(r, {"s.rec", "scene.json", "boxes", "forces.csv", {}});
  EXPECT_EQ(j["schema"], "hapsim.assessment/1");
  EXPECT_NEAR(j["score"]["terms"]["breaches"].get<double>(), -8.75, 1e-9);
  EXPECT_NE(j["score"]["formula"].get<std::string>().find("100 * found / landmarks"),
            std::string::npos);
  EXPECT_TRUE(j["picture"].is_null());
  EXPECT_TRUE(j["landmarks"][3]["found_at_s"].is_null());
  EXPECT_TRUE(j["landmarks"][3]["mean_force_n"].is_null());
}

TEST(AssessmentScorer, ManyBreachesFloorTheScoreAtZero) {
  const auto world = three_boxes();
  AssessmentDefinition def;
  AssessmentLimit limit;
  limit.material = "soft";
  limit.max_force_n = 1.0;
  def.limits = {limit};
  AssessmentScorer scorer(def, *world, kDt);
  for (int i = 0; i < 100; ++i) {
    scorer.add(cycle({{0, 3.0}}));
    scorer.add(cycle({}));
  }
  const AssessmentResult r = scorer.finish();
  EXPECT_EQ(r.breaches.size(), 100u);
  EXPECT_EQ(r.score.value, 0.0);
}

}  // namespace
}  // namespace hapsim
