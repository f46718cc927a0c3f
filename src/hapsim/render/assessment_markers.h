// The landmarks and breaches of an assessment (docs/assessment.md) drawn into a scene: found
// landmarks green (#2ca02c), missed grey (#7f7f7f), a landmark's point with its radius as a wire
// sphere, each breach's worst point red (#d62728). `hapsim assess --report`'s picture and the
// viewer draw them the same way.
#pragma once

#include "hapsim/render/render_scene.h"
#include "hapsim/scene/assessment_definition.h"
#include "hapsim/training/assessment_result.h"
#include "hapsim/world/world_description.h"

#include <span>
#include <vector>

namespace hapsim {

/// Where each landmark is marked: its point; else, of the half of its segment's rest surface
/// nearest the segment's centre, the vertex facing `towards_eye` most (the centre itself is
/// buried in the tissue around it). `X_world_body`: each body's pose.
[[nodiscard]] std::vector<Vec3> landmark_marker_points(const WorldDescription& world,
                                                       std::span<const Iso3> X_world_body,
                                                       const AssessmentDefinition& definition,
                                                       const Vec3& towards_eye);

/// Adds the markers to `scene.spheres` (call after the scene's own per-frame update).
/// `found[i]`: landmark i found; `breach_points`: where each breach peaked.
void add_assessment_markers(RenderScene& scene, const AssessmentDefinition& definition,
                            std::span<const Vec3> marker_points, const std::vector<bool>& found,
                            std::span<const Vec3> breach_points, double marker_m);

}  // namespace hapsim
