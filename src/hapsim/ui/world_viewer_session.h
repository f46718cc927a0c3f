// The viewer's session for a World scene (the knee scenes): the world on the haptic loop, driven
// by the viewer's mouse probe, the scene's script or a 3D mouse; its render scene (WorldScene)
// updated from the loop's snapshots; live controls for display, segments and materials.
#pragma once

#include "hapsim/ui/viewer_session.h"

#include <memory>

namespace hapsim {

struct SceneDescription;

/// Throws hapsim::Error (bad scene, no 3D mouse …); the viewer shows the message.
[[nodiscard]] std::unique_ptr<ViewerSession> make_world_viewer_session(
    const ViewerConfig& config, const SceneDescription& scene);

}  // namespace hapsim
