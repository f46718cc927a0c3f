// A scene's "assessment" (docs/assessment.md): a good one reads into exactly the definition it
// writes; each bad one is one error naming the file and the JSON pointer of the offending value,
// with what was expected (the pointers and fragments are written from docs/scene-format.md).
#include "hapsim/core/error.h"
#include "hapsim/scene/scene_file.h"

#include "support/temp_dir_test.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <string>

namespace hapsim {
namespace {

using Json = nlohmann::json;

class AssessmentReaderTest : public test::TempDirTest {
 protected:
  // Two boxes, "block" (material hard) and "pad" (soft), and a palpation of the block.
  static Json base() {
    return Json::parse(R"({
      "format": "hapsim-scene/1",
      "materials": {
        "hard": { "response": "proxy", "stiffness_n_per_m": 2000 },
        "soft": { "response": "penalty", "stiffness_n_per_m": 300 }
      },
      "bodies": [
        { "name": "block", "geometry": { "box": { "half_extents_m": [0.02, 0.02, 0.02] } },
          "materials": "hard" },
        { "name": "pad", "pose": { "position_m": [0.1, 0, 0] },
          "geometry": { "box": { "half_extents_m": [0.02, 0.02, 0.02] } }, "materials": "soft" }
      ],
      "tools": [ { "name": "tip", "radius_m": 0.005 } ],
      "device": { "profile": "touch",
                  "palpation": { "targets": [ { "body": "block", "segment": "block",
                                                "from": [0, 0, 2] } ] } },
      "assessment": {
        "landmarks": [
          { "name": "top", "segment": "block", "point_m": [0, 0, 0.02], "radius_m": 0.01,
            "force_n": 2.0, "dwell_s": 0.3 },
          { "name": "pad", "body": "pad", "segment": "pad", "force_n": 1.0 }
        ],
        "limits": [ { "segment": "block", "max_force_n": 8 },
                    { "material": "soft", "max_force_n": 3 } ],
        "time_limit_s": 60
      }
    })");
  }

  void expect_error(const Json& scene, const std::string& pointer,
                    const std::string& fragment) const {
    const auto file = write("scene.json", scene.dump(2));
    try {
      (void)load_scene(file);
      ADD_FAILURE() << "loaded; expected " << pointer << ": " << fragment;
    } catch (const Error& e) {
      EXPECT_EQ(e.where(), file.string() + ":" + pointer) << e.what();
      EXPECT_NE(e.detail().find(fragment), std::string::npos)
          << "message: " << e.detail() << "\nexpected: " << fragment;
      const std::string line = e.what();
      EXPECT_EQ(line.find('\n'), std::string::npos) << "not one line: " << line;
    }
  }
};

TEST_F(AssessmentReaderTest, AGoodAssessmentReadsAsWritten) {
  const SceneDescription s = load_scene(write("scene.json", base().dump()));
  ASSERT_TRUE(s.has_assessment);
  const AssessmentDefinition& a = s.assessment;
  ASSERT_EQ(a.landmarks.size(), 2u);
  EXPECT_EQ(a.landmarks[0].name, "top");
  EXPECT_EQ(a.landmarks[0].body, "block");  // the only body with such a segment
  ASSERT_TRUE(a.landmarks[0].point_world.has_value());
  EXPECT_TRUE(a.landmarks[0].point_world->isApprox(Vec3(0, 0, 0.02)));
  EXPECT_DOUBLE_EQ(a.landmarks[0].radius_m, 0.01);
  EXPECT_DOUBLE_EQ(a.landmarks[0].force_n, 2.0);
  EXPECT_DOUBLE_EQ(a.landmarks[0].dwell_s, 0.3);
  EXPECT_FALSE(a.landmarks[1].point_world.has_value());
  EXPECT_DOUBLE_EQ(a.landmarks[1].dwell_s, 0.2);  // the default
  ASSERT_EQ(a.limits.size(), 2u);
  EXPECT_EQ(a.limits[0].tissue(), "block");
  EXPECT_EQ(a.limits[1].tissue(), "soft");
  EXPECT_DOUBLE_EQ(a.limits[1].max_force_n, 3.0);
  ASSERT_TRUE(a.time_limit_s.has_value());
  EXPECT_DOUBLE_EQ(*a.time_limit_s, 60.0);
}

TEST_F(AssessmentReaderTest, ASceneWithoutOneHasNone) {
  Json j = base();
  j.erase("assessment");
  EXPECT_FALSE(load_scene(write("scene.json", j.dump())).has_assessment);
}

TEST_F(AssessmentReaderTest, BadDefinitionsNameTheFileAndThePointer) {
  const std::string lm = "/assessment/landmarks/0";
  {
    Json j = base();
    j["assessment"]["landmarks"][0]["segment"] = "femur";
    expect_error(j, lm + "/segment", "no segment named 'femur'");
  }
  {
    Json j = base();
    j["assessment"]["landmarks"][1]["body"] = "knee";
    expect_error(j, "/assessment/landmarks/1/body", "no body named 'knee'");
  }
  {
    Json j = base();
    j["assessment"]["landmarks"][0]["force_n"] = -1.0;
    expect_error(j, lm + "/force_n", "newtons");
  }
  {
    Json j = base();
    j["assessment"]["landmarks"][0].erase("force_n");
    expect_error(j, lm, "force_n");
  }
  {
    Json j = base();
    j["assessment"]["landmarks"][0].erase("point_m");
    expect_error(j, lm + "/radius_m", "a radius needs a point_m");
  }
  {
    Json j = base();
    j["assessment"]["landmarks"][0].erase("radius_m");
    expect_error(j, lm + "/point_m", "a point needs a radius_m");
  }
  {
    Json j = base();
    j["assessment"]["landmarks"][0]["dwell_s"] = -0.1;
    expect_error(j, lm + "/dwell_s", "seconds");
  }
  {
    Json j = base();
    j["assessment"]["landmarks"][1]["name"] = "top";
    expect_error(j, "/assessment/landmarks/1/name", "unique landmark name");
  }
  {
    Json j = base();
    j["assessment"]["landmarks"][0]["pressure"] = 1;
    expect_error(j, lm + "/pressure", "");
  }
  {
    Json j = base();
    j["assessment"]["limits"][1]["material"] = "bone";
    expect_error(j, "/assessment/limits/1/material", "no material named 'bone'");
  }
  {
    Json j = base();
    j["assessment"]["limits"][0]["material"] = "hard";
    expect_error(j, "/assessment/limits/0", "one of \"segment\" and \"material\"");
  }
  {
    Json j = base();
    j["assessment"]["limits"][0]["max_force_n"] = 0;
    expect_error(j, "/assessment/limits/0/max_force_n", "newtons");
  }
  {
    Json j = base();
    j["assessment"]["limits"][1] = {{"segment", "block"}, {"max_force_n", 2}};
    expect_error(j, "/assessment/limits/1", "one limit per tissue");
  }
  {
    Json j = base();
    j["assessment"]["time_limit_s"] = "soon";
    expect_error(j, "/assessment/time_limit_s", "");
  }
  {
    Json j = base();
    j["assessment"]["landmarks"] = Json::object();
    expect_error(j, "/assessment/landmarks", "list of landmarks");
  }
}

}  // namespace
}  // namespace hapsim
