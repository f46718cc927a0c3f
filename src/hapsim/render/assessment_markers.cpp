#include "hapsim/render/assessment_markers.h"

#include <algorithm>
#include <limits>

namespace hapsim {
namespace {

// The contract's colours (docs/assessment.md, "Output").
const Vec3f kFoundColour(0x2c / 255.0f, 0xa0 / 255.0f, 0x2c / 255.0f);
const Vec3f kMissedColour(0x7f / 255.0f, 0x7f / 255.0f, 0x7f / 255.0f);
const Vec3f kBreachColour(0xd6 / 255.0f, 0x27 / 255.0f, 0x28 / 255.0f);

Vec3 segment_marker(const TriangleMesh& mesh, const Iso3& X_world_body, const Vec3& towards_eye) {
  if (mesh.vertices.empty()) {
    return X_world_body.translation();
  }
  Vec3 centre = Vec3::Zero();
  for (const Vec3& v : mesh.vertices) {
    centre += v;
  }
  centre /= static_cast<double>(mesh.vertices.size());
  std::vector<double> distance;
  distance.reserve(mesh.vertices.size());
  for (const Vec3& v : mesh.vertices) {
    distance.push_back((v - centre).norm());
  }
  std::vector<double> sorted = distance;
  const auto middle = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2);
  std::nth_element(sorted.begin(), middle, sorted.end());
  Vec3 best = X_world_body * centre;
  double best_along = -std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < mesh.vertices.size(); ++k) {
    const Vec3 p = X_world_body * mesh.vertices[k];
    if (distance[k] <= *middle && p.dot(towards_eye) > best_along) {
      best_along = p.dot(towards_eye);
      best = p;
    }
  }
  return best;
}

}  // namespace

std::vector<Vec3> landmark_marker_points(const WorldDescription& world,
                                         std::span<const Iso3> X_world_body,
                                         const AssessmentDefinition& definition,
                                         const Vec3& towards_eye) {
  std::vector<Vec3> points;
  for (const AssessmentLandmark& l : definition.landmarks) {
    if (l.point_world) {
      points.push_back(*l.point_world);
      continue;
    }
    Vec3 at = Vec3::Zero();
    for (std::size_t b = 0; b < world.bodies.size() && b < X_world_body.size(); ++b) {
      if (world.bodies[b].name != l.body) {
        continue;
      }
      for (const SegmentDescription& s : world.bodies[b].segments) {
        if (s.name == l.segment) {
          at = segment_marker(s.mesh, X_world_body[b], towards_eye);
        }
      }
    }
    points.push_back(at);
  }
  return points;
}

void add_assessment_markers(RenderScene& scene, const AssessmentDefinition& definition,
                            std::span<const Vec3> marker_points, const std::vector<bool>& found,
                            std::span<const Vec3> breach_points, double marker_m) {
  for (std::size_t i = 0; i < marker_points.size() && i < definition.landmarks.size(); ++i) {
    const AssessmentLandmark& l = definition.landmarks[i];
    const Vec3f colour = i < found.size() && found[i] ? kFoundColour : kMissedColour;
    scene.spheres.push_back({marker_points[i], marker_m, colour, false});
    if (l.point_world) {
      scene.spheres.push_back({*l.point_world, l.radius_m, colour, true});
    }
  }
  for (const Vec3& p : breach_points) {
    scene.spheres.push_back({p, 1.2 * marker_m, kBreachColour, false});
  }
}

}  // namespace hapsim
