#include "hapsim/ui/viewer_scenes.h"

#include "hapsim/scene/scene_description.h"
#include "hapsim/ui/world_viewer_session.h"

namespace hapsim {

std::unique_ptr<ViewerSession> make_viewer_session(const ViewerConfig& config,
                                                   const SceneDescription& scene) {
  return make_world_viewer_session(config, scene);
}

}  // namespace hapsim
