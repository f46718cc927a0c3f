// The glove's virtual hand as a figure (the knee paper's Fig. 6): palm, thumb metacarpal and the
// fingers' phalanges as shaded capsules at the joint frames the hand model computes from the
// glove's angles, so each finger bends as it is read (the DIP joint following the PIP by the
// coupling) and each fingertip's capsule ends where its tool is.
#pragma once

#include "hapsim/kinematics/hand_model.h"
#include "hapsim/render/render_scene.h"

#include <vector>

namespace hapsim {

/// A nitrile-glove purple: apart from the skin, bone and sheet colours the hand touches.
inline const Vec3f kHandColour(0.60f, 0.55f, 0.85f);

/// Appends the hand's capsules for `reading` (world frame): per finger three phalanges from the
/// MCP through the PIP and DIP to the fingertip sphere's centre, tapering to the fingertip's
/// radius; the palm as a fan of capsules from the wrist to the four finger MCPs, the thumb's
/// metacarpal, and a wrist stub.
void add_hand_figure(const HandModel& hand, const GloveReading& reading, const Vec3f& colour,
                     std::vector<RenderCapsule>& capsules);

}  // namespace hapsim
