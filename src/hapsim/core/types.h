// Eigen aliases used across hapsim. All quantities are SI (metres, newtons, seconds, radians)
// unless a name says otherwise (`_mm`, `_deg`).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <limits>

namespace hapsim {

using Vec3 = Eigen::Vector3d;
using Vec3f = Eigen::Vector3f;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;
using Iso3 = Eigen::Isometry3d;
using Box3 = Eigen::AlignedBox3d;

/// Vertex indices of one triangle, counter-clockwise seen from outside (outward normal).
using TriangleIndices = std::array<std::uint32_t, 3>;

/// Marks "no triangle" in query results and hints.
inline constexpr std::uint32_t kNoTriangle = std::numeric_limits<std::uint32_t>::max();

inline constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace hapsim
