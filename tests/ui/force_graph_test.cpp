// The force graph's scale and labels, without a window: the full scale follows the device and
// the scene (force_scale.h), grows to a nice value past a force that exceeded it, and every
// value and label is fitted to its bar's slot so neighbours never overlap.
#include "hapsim/ui/force_graph.h"

#include "hapsim/render/force_scale.h"
#include "hapsim/scene/scene_file.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace hapsim {
namespace {

TEST(ForceScale, NiceCeilingsAreTheNextStepUp) {
  EXPECT_DOUBLE_EQ(nice_force_ceiling_n(4.0), 4.0);
  EXPECT_DOUBLE_EQ(nice_force_ceiling_n(4.01), 5.0);
  EXPECT_DOUBLE_EQ(nice_force_ceiling_n(12.0), 15.0);
  EXPECT_DOUBLE_EQ(nice_force_ceiling_n(0.7), 0.8);
  EXPECT_DOUBLE_EQ(nice_force_ceiling_n(9.0), 10.0);
  EXPECT_DOUBLE_EQ(nice_force_ceiling_n(100.0), 100.0);
  EXPECT_DOUBLE_EQ(nice_force_ceiling_n(-1.0), 1.0);
}

TEST(ForceScale, ShippedScenesFitTheirForcesNotAHundredNewtons) {
  const auto scene = [](const char* file) {
    return load_scene(std::filesystem::path(HAPSIM_SOURCE_DIR) / "scenes" / file);
  };
  // The knee on a simulated device rated 100 N: its contacts saturate at a few newtons.
  const SceneDescription knee = scene("knee_paper.json");
  double largest = 0.0;
  for (const BodyDescription& b : knee.world.bodies) {
    for (const SegmentDescription& seg : b.segments) {
      largest = std::max(largest, knee.world.materials.at(seg.material).contact.max_force_n);
    }
  }
  EXPECT_DOUBLE_EQ(force_display_scale_n(knee.world, 100.0), nice_force_ceiling_n(largest));
  EXPECT_LT(force_display_scale_n(knee.world, 100.0), 100.0);
  // The glove: each finger is rated 4 N, less than the knee's materials.
  const SceneDescription hand = scene("knee_hand_procedural.json");
  EXPECT_DOUBLE_EQ(force_display_scale_n(hand.world, 4.0), 4.0);
  // A scene softer than its device: the scene's own ceiling.
  WorldDescription soft;
  MaterialDescription m;
  m.contact.max_force_n = 2.2;
  soft.materials.push_back(m);
  BodyDescription b;
  b.segments.emplace_back();
  soft.bodies.push_back(b);
  EXPECT_DOUBLE_EQ(force_display_scale_n(soft, 12.0), 2.5);
}

TEST(ForceGraph, ScaleGrowsPastAForceThatExceededIt) {
  ForceGraph g;
  g.push({{"index", 3.0}, {"middle", 1.0}});
  EXPECT_DOUBLE_EQ(g.display_scale_n(4.0), 4.0);
  g.push({{"index", 6.3}, {"middle", 1.0}});
  EXPECT_DOUBLE_EQ(g.display_scale_n(4.0), 8.0);
}

TEST(ForceGraph, ValuesAndLabelsFitTheirSlots) {
  // 7 px a character, as a monospaced font.
  const auto width = [](const std::string& t) { return 7.0f * static_cast<float>(t.size()); };
  EXPECT_EQ(ForceGraph::fit_text({"12.34 N", "12.3", "12"}, 60.0f, width), "12.34 N");
  EXPECT_EQ(ForceGraph::fit_text({"12.34 N", "12.3", "12"}, 30.0f, width), "12.3");
  EXPECT_EQ(ForceGraph::fit_text({"12.34 N", "12.3", "12"}, 20.0f, width), "12");
  EXPECT_EQ(ForceGraph::fit_text({"thumb"}, 30.0f, width), "thu.");
  EXPECT_EQ(ForceGraph::fit_text({"thumb"}, 5.0f, width), "");
  // Five fingers in a 250 px column: every fitted label within its 50 px slot (less the gap).
  for (const char* label : {"thumb", "index", "middle", "ring", "little", "pad 1 (left)"}) {
    EXPECT_LE(width(ForceGraph::fit_text({label}, 46.0f, width)), 46.0f) << label;
  }
}

}  // namespace
}  // namespace hapsim
