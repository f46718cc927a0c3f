// Which viewer session a scene gets: a World scene (the knee scenes) or a teleoperation scene.
#pragma once

#include "hapsim/ui/viewer_session.h"

#include <memory>

namespace hapsim {

struct SceneDescription;

[[nodiscard]] std::unique_ptr<ViewerSession> make_viewer_session(const ViewerConfig& config,
                                                                 const SceneDescription& scene);

}  // namespace hapsim
