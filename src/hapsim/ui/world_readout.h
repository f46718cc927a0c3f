// What a viewer session shows of a World scene, shared by the session that runs the world itself
// (world_viewer_session.h) and the one that draws a world served by another process
// (net_viewer_session.h): the data area's readout from a snapshot, and the display controls.
#pragma once

#include "hapsim/render/world_scene.h"
#include "hapsim/ui/viewer_session.h"

#include <string>

namespace hapsim {

/// Tools, force bars, what is touched and the device pose, from `s` (a scene without a rig).
void fill_world_readout(const World& world, const WorldScene& view, const WorldSnapshot& s,
                        SessionReadout& readout);

/// ImGui widgets: colouring, sphere-tree level, proxies and arrows, and each segment's
/// visibility.
void draw_world_display_controls(WorldScene& view);

/// "x y z" in millimetres, aligned for the data area.
[[nodiscard]] std::string format_mm(const Vec3& p_m);

}  // namespace hapsim
