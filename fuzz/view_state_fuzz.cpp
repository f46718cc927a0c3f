// Fuzz target: raw bytes as a received hapsim_msg_ViewState through net::ViewStateDecoder (a
// connected viewer's side: what it draws of a world another process runs). The world is the
// procedural knee with the glove's hand (scenes/knee_hand_procedural.json), built once. Checks,
// for any bytes:
//  * a refused sample changes nothing of the viewer's snapshot and says why;
//  * an accepted one leaves every number the viewer draws finite: tools, contacts (naming a tool,
//    body and segment the scene has), body poses (rigid: unit rotation), deflections, every
//    vertex, the hand's pose and angles.
//
// Input layout (see fuzz/make_seed_corpus.py): a control byte, then the fixed fields in IDL order
// (little-endian), then for each sequence (bodies, deflection_m, offsets, contacts) a 16-bit
// length and its elements, read while bytes last. Control bit 0 gives the sample this world's
// scene hash and its tool count; bit 1 sizes bodies and deflection_m to the world's (cut, or
// padded with rest poses and zero deflection), so most inputs reach the per-element checks.
#include "fuzz_support.h"
#include "hapsim/net/view_state_codec.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#ifndef HAPSIM_SOURCE_DIR
#error "HAPSIM_SOURCE_DIR: the repository, for the scene this target decodes against"
#endif

namespace {

constexpr std::uint64_t kSceneHash = 0x68617073696d2121ULL;
// A sequence longer than this is cut (a DDS sample of millions of elements is Cyclone's to
// refuse; the decoder's checks are per element).
constexpr std::uint16_t kMaxElements = 4096;

struct Viewer {
  hapsim::RunSetup setup = hapsim::make_run_setup(
      hapsim::load_scene(std::string(HAPSIM_SOURCE_DIR) + "/scenes/knee_hand_procedural.json"),
      hapsim::DeviceChoice::scene_script());
  hapsim::World& world = *setup.world;
  hapsim::net::ViewStateDecoder decoder{world};
  hapsim::WorldSnapshot rest = hapsim::make_world_snapshot(world);
};

Viewer& viewer() {
  static Viewer v;  // built once: a knee takes far longer than any input
  return v;
}

// A 16-bit length, then that many elements (at most kMaxElements), each read by `read_element`.
template <typename T, typename ReadElement>
std::vector<T> read_sequence(hapsim::fuzz::FieldReader& r, ReadElement read_element) {
  std::uint16_t length = 0;
  r.read(length);
  std::vector<T> out(std::min(length, kMaxElements));
  for (T& element : out) {
    read_element(element);
  }
  return out;
}

bool finite(const hapsim::Vec3& v) {
  return v.allFinite();
}

bool same_snapshot(const hapsim::WorldSnapshot& a, const hapsim::WorldSnapshot& b) {
  if (a.cycle != b.cycle || a.contact_count != b.contact_count ||
      a.positions_body != b.positions_body || a.deflection_m != b.deflection_m ||
      a.positions_version != b.positions_version || a.hand.angles_rad != b.hand.angles_rad ||
      !a.hand.X_world_hand.isApprox(b.hand.X_world_hand, 0.0) ||
      a.body_poses_world.size() != b.body_poses_world.size()) {
    return false;
  }
  for (std::size_t i = 0; i < a.body_poses_world.size(); ++i) {
    if (!a.body_poses_world[i].isApprox(b.body_poses_world[i], 0.0)) {
      return false;
    }
  }
  for (std::size_t t = 0; t < a.tools.size(); ++t) {
    if (a.tools[t].p_world != b.tools[t].p_world || a.tool_force_n[t] != b.tool_force_n[t]) {
      return false;
    }
  }
  return true;
}

}  // namespace

// The world is built here, before the first input: built inside one, on a machine busy with
// other work, it took longer than an input's time limit and libFuzzer reported the (empty) first
// input as a timeout.
extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  (void)viewer();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Viewer& v = viewer();
  hapsim::fuzz::FieldReader r(data, size);
  std::uint8_t control = 0;
  r.read(control);
  hapsim_msg_ViewState m{};
  r.read(m.scene_hash);
  r.read(m.serve_id);
  r.read(m.cycle);
  r.read(m.sim_time_s);
  r.read_bool(m.device_host_driving);
  r.read_bool(m.paused);
  r.read(m.device_p_m);
  r.read(m.device_q_wxyz);
  r.read(m.command_force_n);
  r.read(m.tool_count);
  for (hapsim_msg_ToolView& t : m.tools) {
    r.read(t.p_m);
    r.read(t.proxy_m);
    r.read(t.force_n);
    r.read(t.rendered_force_n);
    r.read(t.contact_count);
  }
  r.read(m.hand_p_m);
  r.read(m.hand_q_wxyz);
  r.read(m.hand_angles_rad);
  auto bodies = read_sequence<hapsim_msg_BodyPose>(r, [&](hapsim_msg_BodyPose& b) {
    r.read(b.p_m);
    r.read(b.q_wxyz);
  });
  auto deflection_m = read_sequence<float>(r, [&](float& d) { r.read(d); });
  if ((control & 2U) != 0) {  // the world's counts: bodies at rest, segments undeflected
    bodies.resize(v.rest.body_poses_world.size(), hapsim_msg_BodyPose{{0, 0, 0}, {1, 0, 0, 0}});
    deflection_m.resize(v.rest.deflection_m.size(), 0.0f);
  }
  auto offsets = read_sequence<hapsim_msg_VertexOffset>(r, [&](hapsim_msg_VertexOffset& o) {
    r.read(o.segment);
    r.read(o.vertex);
    r.read(o.offset_m);
  });
  auto contacts = read_sequence<hapsim_msg_ContactView>(r, [&](hapsim_msg_ContactView& c) {
    r.read(c.tool);
    r.read(c.body);
    r.read(c.segment);
    r.read(c.point_m);
    r.read(c.normal);
    r.read(c.depth_m);
    r.read(c.force_n);
    r.read_bool(c.proxy);
  });
  if ((control & 1U) != 0) {
    m.scene_hash = kSceneHash;
    m.tool_count = static_cast<std::uint16_t>(v.rest.tools.size());
  }
  const auto point_at = [](auto& seq, auto& vec) {
    seq._buffer = vec.data();
    seq._length = static_cast<std::uint32_t>(vec.size());
    seq._maximum = seq._length;
    seq._release = false;
  };
  point_at(m.bodies, bodies);
  point_at(m.deflection_m, deflection_m);
  point_at(m.offsets, offsets);
  point_at(m.contacts, contacts);

  // Each input decodes into a fresh copy of the rest snapshot. The decoder is built once (it
  // copies the world's surfaces) and remembers what the last accepted sample moved, to put it
  // back first: the rest copy already has it there.
  hapsim::WorldSnapshot seen = v.rest;
  std::string why;
  if (!v.decoder.decode(m, kSceneHash, seen, why)) {
    HAPSIM_FUZZ_CHECK(!why.empty(), "a refused sample says why");
    HAPSIM_FUZZ_CHECK(same_snapshot(seen, v.rest), "a refused sample changed the snapshot");
    return 0;
  }
  HAPSIM_FUZZ_CHECK(
      std::isfinite(seen.time_s) && finite(seen.input.p_world) && finite(seen.output.force_world_n),
      "accepted header not finite");
  for (std::size_t t = 0; t < seen.tools.size(); ++t) {
    HAPSIM_FUZZ_CHECK(finite(seen.tools[t].p_world) && finite(seen.tools[t].proxy_world) &&
                          finite(seen.tools[t].force_world_n) &&
                          std::isfinite(seen.tool_force_n[t]),
                      "accepted tool not finite");
  }
  for (const hapsim::Iso3& X : seen.body_poses_world) {
    HAPSIM_FUZZ_CHECK(X.matrix().allFinite(), "accepted body pose not finite");
    HAPSIM_FUZZ_CHECK(
        (X.linear().transpose() * X.linear() - hapsim::Mat3::Identity()).norm() < 1e-9,
        "accepted body pose not a rotation");
  }
  HAPSIM_FUZZ_CHECK(seen.hand.X_world_hand.matrix().allFinite(), "accepted hand pose not finite");
  for (const auto& finger : seen.hand.angles_rad) {
    for (const double a : finger) {
      HAPSIM_FUZZ_CHECK(std::isfinite(a), "accepted hand angle not finite");
    }
  }
  for (const double d : seen.deflection_m) {
    HAPSIM_FUZZ_CHECK(std::isfinite(d), "accepted deflection not finite");
  }
  for (const auto& xyz : seen.positions_body) {
    for (const float x : xyz) {
      HAPSIM_FUZZ_CHECK(std::isfinite(x), "accepted vertex not finite");
    }
  }
  HAPSIM_FUZZ_CHECK(seen.contact_count <= seen.contacts.size(), "more contacts than room");
  for (std::size_t i = 0; i < seen.contact_count; ++i) {
    const hapsim::WorldContact& c = seen.contacts[i];
    HAPSIM_FUZZ_CHECK(c.tool.valid() && c.tool.index() < seen.tools.size() && c.body.valid() &&
                          c.body.index() < v.world.body_count() && c.segment.valid() &&
                          c.segment.index() < v.world.segment_count(c.body.index()),
                      "accepted contact names a tool, body or segment the scene lacks");
    HAPSIM_FUZZ_CHECK(finite(c.point_world) && finite(c.normal_world) && std::isfinite(c.force_n) &&
                          std::isfinite(c.depth_m),
                      "accepted contact not finite");
  }
  return 0;
}
