// The viewer's session for a world served by another process (`hapsim view --connect`): it finds
// the simulation host of its session (`hapsim serve`, SceneInfo), builds the same scene here (the
// scene hash must match), and draws the host's ViewState samples as they come: tools, contacts,
// bodies and the current deformation (complete in every sample, so joining late is no different).
// No haptic loop and no device here: the device host feels, this one only shows.
#pragma once

#include "hapsim/ui/viewer_session.h"

#include <memory>

namespace hapsim {

/// Waits up to config.connect_timeout_s for a simulation host in config.session. Throws
/// hapsim::Error when none comes or its scene cannot be built here.
[[nodiscard]] std::unique_ptr<ViewerSession> make_net_viewer_session(const ViewerConfig& config);

}  // namespace hapsim
