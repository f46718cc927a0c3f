// A running world as a viewer on another process sees it (net/idl ViewState): tools, contacts,
// body poses, every vertex of a deformed surface that is away from its rest position, and a rig's
// master, slave joints and grasp (drawn as in one process). The
// message is complete, not a delta, so a viewer that joins late (or lost samples) draws the
// current deformation from the next one it gets. Both sides know the rest surfaces: they build
// the same world from the same scene (SceneInfo), checked by the scene hash.
// Off the haptic path: the simulation host encodes from the loop's snapshot at display rate.
#pragma once

#include "hapsim/kinematics/master_arm.h"
#include "hapsim/runtime/world_snapshot.h"
#include "hapsim_messages.h"

#include <cstdint>
#include <string>
#include <vector>

namespace hapsim::net {

/// A vertex this close to its rest position is at rest (float positions: 1 µm is far below
/// what a viewer can show and above float rounding of a body-frame coordinate).
inline constexpr float kRestTolerance_m = 1e-6f;

class ViewStateEncoder {
 public:
  /// `world` at rest (before it has stepped): its surfaces are the rest positions.
  explicit ViewStateEncoder(const World& world);

  /// The message for `snapshot`; its sequences point into this encoder's buffers (valid until
  /// the next encode).
  [[nodiscard]] const hapsim_msg_ViewState& encode(const WorldSnapshot& snapshot,
                                                   std::uint64_t scene_hash, std::uint64_t serve_id,
                                                   bool host_driving, bool paused = false);

 private:
  std::vector<std::vector<float>> rest_body_;  ///< per flat segment, as in WorldSnapshot
  std::vector<hapsim_msg_BodyPose> bodies_;
  std::vector<float> deflection_m_;
  std::vector<hapsim_msg_VertexOffset> offsets_;
  std::vector<hapsim_msg_ContactView> contacts_;
  hapsim_msg_ViewState message_{};
};

class ViewStateDecoder {
 public:
  /// `world`: the viewer's own build of the scene, at rest.
  explicit ViewStateDecoder(const World& world);

  /// Writes `m` into `snapshot` (made by make_world_snapshot for the same world). False, with
  /// `why` and `snapshot` untouched, when the message does not fit the world: another scene, a
  /// body or segment count that differs, an index out of range, a non-finite number.
  bool decode(const hapsim_msg_ViewState& m, std::uint64_t scene_hash, WorldSnapshot& snapshot,
              std::string& why);

 private:
  std::vector<std::vector<float>> rest_body_;
  /// Per flat segment: the vertices the last applied message moved (put back when a later one
  /// no longer lists them).
  std::vector<std::vector<std::uint32_t>> moved_;
  std::vector<std::uint64_t> versions_;
  std::vector<std::size_t> segments_per_body_;
  std::vector<bool> changed_;
  const MasterArm* master_ = nullptr;  ///< a rig's, for the hand its joints put
};

}  // namespace hapsim::net
