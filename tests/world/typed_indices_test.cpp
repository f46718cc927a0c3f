// Typed indices (world/indices.h, architecture.md Notation "Indices"): flat_segment maps a
// body-local segment to the flat one in a world of several bodies; a contact's LocalSegment names
// the segment within its body, not the flat one; the two segment numberings do not convert into
// each other; and typing the fields left the records on the haptic path the same size.
#include "hapsim/geometry/procedural.h"
#include "hapsim/runtime/cycle_record.h"
#include "hapsim/world/indices.h"
#include "hapsim/world/world.h"

#include <gtest/gtest.h>

#include <type_traits>

namespace hapsim {
namespace {

// The two numberings of a segment never convert into each other, nor to or from a plain integer.
static_assert(!std::is_convertible_v<FlatSegment, LocalSegment>);
static_assert(!std::is_convertible_v<LocalSegment, FlatSegment>);
static_assert(!std::is_constructible_v<LocalSegment, FlatSegment>);
static_assert(!std::is_constructible_v<FlatSegment, LocalSegment>);
static_assert(!std::is_convertible_v<BodyIndex, LocalSegment>);
static_assert(!std::is_convertible_v<ToolIndex, BodyIndex>);
static_assert(!std::is_convertible_v<std::int32_t, LocalSegment>);
static_assert(!std::is_convertible_v<LocalSegment, std::int32_t>);
static_assert(std::is_constructible_v<LocalSegment, std::int32_t>);  // explicitly
// A body-local index where a flat one is expected does not compile.
static_assert(!std::is_invocable_v<decltype(&WorldModel::flat_segment), const WorldModel&,
                                   BodyIndex, FlatSegment>);
static_assert(std::is_same_v<decltype(std::declval<const World&>().flat_segment(BodyIndex{0},
                                                                                LocalSegment{0})),
                             FlatSegment>);

// Each index is the integer it replaced, so the records that hold them kept their layout (sizes
// measured before the change; CycleRecord holds kMaxCycleContacts WorldContacts).
static_assert(sizeof(ToolIndex) == 4 && sizeof(BodyIndex) == 4 && sizeof(LocalSegment) == 4 &&
              sizeof(FlatSegment) == 4);
static_assert(std::is_trivially_copyable_v<ToolIndex> && std::is_trivially_copyable_v<BodyIndex> &&
              std::is_trivially_copyable_v<LocalSegment> &&
              std::is_trivially_copyable_v<FlatSegment>);
static_assert(sizeof(WorldContact) == 88);
static_assert(sizeof(BodyContact) == 96);
static_assert(sizeof(PenaltyCandidate) == 96);
static_assert(sizeof(CycleRecord) ==
              8176);  // 8048 before the rig reported its tool force and slave torques

// The sentinels keep their −1.
static_assert(kNoSegment.value == -1 && !kNoSegment.valid());
static_assert(kNoBody.value == -1 && kNoTool.value == -1);
static_assert(LocalSegment{0} < LocalSegment{1} && FlatSegment{3} == FlatSegment{3});

SegmentDescription box_segment(const char* name, double x_m) {
  SegmentDescription seg;
  seg.name = name;
  seg.mesh = make_box(Vec3(0.01, 0.01, 0.01));
  for (Vec3& v : seg.mesh.vertices) {
    v += Vec3(x_m, 0.0, -0.01);  // top face at z = 0
  }
  return seg;
}

// Body 0 ("left"): two segments; body 1 ("right"): three, flat 2, 3, 4. Each segment a 2 cm cube
// with its top at z = 0, 5 cm apart along x.
WorldDescription three_and_two() {
  WorldDescription w;
  w.name = "typed indices";
  MaterialDescription m;
  m.name = "tissue";
  m.response = ContactResponse::kPenalty;
  m.contact.stiffness_n_per_m = 500.0;
  m.contact.max_penetration_m = 0.01;
  m.contact.max_force_n = 4.0;
  w.materials.push_back(m);
  BodyDescription left;
  left.name = "left";
  left.segments.push_back(box_segment("l0", -0.20));
  left.segments.push_back(box_segment("l1", -0.15));
  w.bodies.push_back(std::move(left));
  BodyDescription right;
  right.name = "right";
  right.segments.push_back(box_segment("r0", 0.00));
  right.segments.push_back(box_segment("r1", 0.05));
  right.segments.push_back(box_segment("r2", 0.10));
  w.bodies.push_back(std::move(right));
  ToolDescription tool;
  tool.name = "tip";
  tool.radius_m = 0.0;
  w.tools.push_back(tool);
  return w;
}

TEST(TypedIndices, DefaultContactsNameNothing) {
  EXPECT_EQ(WorldContact{}.tool, kNoTool);
  EXPECT_EQ(WorldContact{}.body, kNoBody);
  EXPECT_EQ(WorldContact{}.segment, kNoSegment);
  EXPECT_EQ(BodyContact{}.other_body, kNoBody);
  EXPECT_EQ(BodyContact{}.other_segment, kNoSegment);
  EXPECT_EQ(kNoSegment.value, -1);
  EXPECT_FALSE(kNoSegment.valid());
  EXPECT_TRUE(LocalSegment{0}.valid());
}

TEST(TypedIndices, FlatSegmentCountsEveryBodysSegmentsBodyByBody) {
  const World world(three_and_two());
  ASSERT_EQ(world.flat_segment_count(), 5u);
  EXPECT_EQ(world.flat_segment(BodyIndex{0}, LocalSegment{0}), FlatSegment{0});
  EXPECT_EQ(world.flat_segment(BodyIndex{0}, LocalSegment{1}), FlatSegment{1});
  EXPECT_EQ(world.flat_segment(BodyIndex{1}, LocalSegment{0}), FlatSegment{2});
  EXPECT_EQ(world.flat_segment(BodyIndex{1}, LocalSegment{1}), FlatSegment{3});
  EXPECT_EQ(world.flat_segment(BodyIndex{1}, LocalSegment{2}), FlatSegment{4});
  const WorldModel& model = world.model();
  EXPECT_EQ(model.bodies()[1].first_segment, FlatSegment{2});
  // And back: each flat segment knows its body and its place there.
  for (std::size_t b = 0; b < world.body_count(); ++b) {
    for (std::size_t s = 0; s < world.segment_count(b); ++s) {
      const FlatSegment flat = world.flat_segment(BodyIndex{b}, LocalSegment{s});
      const SegmentModel& seg = model.segments()[flat.index()];
      EXPECT_EQ(seg.body, b);
      EXPECT_EQ(seg.index_in_body, LocalSegment{s});
      EXPECT_EQ(seg.description->name, world.description().bodies[b].segments[s].name);
    }
  }
}

TEST(TypedIndices, AContactNamesItsSegmentWithinItsBody) {
  World world(three_and_two());
  DeviceInput in;
  in.p_world = Vec3(0.05, 0.0, -0.002);  // 2 mm into "r1": the second body's second segment
  const StepResult& r = world.step(in, 1e-3);
  ASSERT_EQ(r.contacts.size(), 1u);
  const WorldContact& c = r.contacts[0];
  EXPECT_EQ(c.tool, ToolIndex{0});
  EXPECT_EQ(c.body, BodyIndex{1});
  EXPECT_EQ(c.segment, LocalSegment{1}) << "body-local, not the flat 3";
  EXPECT_EQ(world.description().bodies[c.body.index()].segments[c.segment.index()].name, "r1");
  EXPECT_EQ(world.flat_segment(c.body, c.segment), FlatSegment{3});
  EXPECT_NEAR(c.depth_m, 0.002, 1e-12);
  // The penalty candidate behind it carries the flat index.
  const ToolRuntime& tool = world.state().tools[0];
  ASSERT_EQ(tool.penalty_count, 1u);
  EXPECT_EQ(tool.penalty[0].segment, FlatSegment{3});
}

}  // namespace
}  // namespace hapsim
