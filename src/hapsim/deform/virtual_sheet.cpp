#include "hapsim/deform/virtual_sheet.h"

#include "hapsim/collision/point_triangle.h"
#include "hapsim/core/error.h"
#include "hapsim/geometry/procedural.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

namespace hapsim {

namespace {

bool finite3(const Vec3& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

}  // namespace

VirtualSheet::VirtualSheet(VirtualSheetOptions options, std::unique_ptr<const SheetProfile> profile)
    : n_(options.nodes_per_side),
      side_m_(options.side_m),
      max_depth_m_(options.max_depth_m),
      profile_(std::move(profile)) {
  if (n_ < 2) {
    throw Error("VirtualSheetOptions.nodes_per_side",
                "expected at least 2 nodes per side, got " + std::to_string(n_));
  }
  if (!std::isfinite(side_m_) || side_m_ <= 0.0) {
    throw Error("VirtualSheetOptions.side_m",
                "expected a finite side > 0 m, got " + std::to_string(side_m_));
  }
  if (std::isnan(max_depth_m_) || max_depth_m_ <= 0.0) {
    throw Error("VirtualSheetOptions.max_depth_m",
                "expected a depth > 0 m (or infinity), got " + std::to_string(max_depth_m_));
  }
  if (!profile_) {
    profile_ = std::make_unique<GaussianSheetProfile>();
  }
  const double influence_m = profile_->influence_radius_m();
  if (!std::isfinite(influence_m) || influence_m <= 0.0) {
    throw Error("VirtualSheet profile",
                "expected a finite influence radius > 0 m, got " + std::to_string(influence_m));
  }
  spacing_m_ = side_m_ / (n_ - 1);
  const std::size_t nodes = static_cast<std::size_t>(n_) * static_cast<std::size_t>(n_);
  elastic_z_.assign(nodes, 0.0);
  surface_z_.assign(nodes, 0.0);
  mesh_ = std::make_unique<TriangleMesh>(make_sheet(n_, side_m_));
  mesh_->vertex_normals.assign(nodes, Vec3::UnitZ());
}

void VirtualSheet::node_range(double c, double radius, int& lo, int& hi) const {
  const double half = 0.5 * side_m_;
  const double lo_f = std::ceil((c - radius + half) / spacing_m_);
  const double hi_f = std::floor((c + radius + half) / spacing_m_);
  // Clamp in double first: a far-away point must not overflow the int conversion.
  lo = static_cast<int>(std::clamp(lo_f, 0.0, static_cast<double>(n_)));
  hi = static_cast<int>(std::clamp(hi_f, -1.0, static_cast<double>(n_ - 1)));
}

// haptic path
void VirtualSheet::apply_contacts(std::span<const SheetContact> contacts) {
  std::fill(elastic_z_.begin(), elastic_z_.end(), 0.0);
  const double half = 0.5 * side_m_;
  const double influence_m = profile_->influence_radius_m();
  for (const SheetContact& contact : contacts) {
    if (!finite3(contact.p_sheet) || !std::isfinite(contact.force_n)) {
      ++rejected_;
      continue;
    }
    const double force_n = std::max(contact.force_n, 0.0);
    if (force_n == 0.0) {
      continue;
    }
    int i_lo = 0, i_hi = 0, j_lo = 0, j_hi = 0;
    node_range(contact.p_sheet.x(), influence_m, i_lo, i_hi);
    node_range(contact.p_sheet.y(), influence_m, j_lo, j_hi);
    for (int j = j_lo; j <= j_hi; ++j) {
      const double dy = -half + j * spacing_m_ - contact.p_sheet.y();
      for (int i = i_lo; i <= i_hi; ++i) {
        const double dx = -half + i * spacing_m_ - contact.p_sheet.x();
        const double depth_m = profile_->depth_m(std::sqrt(dx * dx + dy * dy), force_n);
        // A user profile returning NaN/negative must not poison or lift the sheet.
        if (depth_m > 0.0 && std::isfinite(depth_m)) {
          elastic_z_[static_cast<std::size_t>(j * n_ + i)] -= depth_m;
        }
      }
    }
  }
  for (double& z : elastic_z_) {
    z = std::max(z, -max_depth_m_);
  }
  std::copy(elastic_z_.begin(), elastic_z_.end(), surface_z_.begin());
  write_mesh();
}

// haptic path
void VirtualSheet::imprint_sphere(const Vec3& center_sheet, double radius_m) {
  if (!finite3(center_sheet) || !std::isfinite(radius_m) || radius_m < 0.0) {
    ++rejected_;
    return;
  }
  const double half = 0.5 * side_m_;
  int i_lo = 0, i_hi = 0, j_lo = 0, j_hi = 0;
  node_range(center_sheet.x(), radius_m, i_lo, i_hi);
  node_range(center_sheet.y(), radius_m, j_lo, j_hi);
  const double r2 = radius_m * radius_m;
  bool changed = false;
  for (int j = j_lo; j <= j_hi; ++j) {
    const double dy = -half + j * spacing_m_ - center_sheet.y();
    for (int i = i_lo; i <= i_hi; ++i) {
      const double dx = -half + i * spacing_m_ - center_sheet.x();
      const double d2 = dx * dx + dy * dy;
      if (d2 >= r2) {
        continue;
      }
      const double cap_z = std::max(center_sheet.z() - std::sqrt(r2 - d2), -max_depth_m_);
      double& z = surface_z_[static_cast<std::size_t>(j * n_ + i)];
      if (cap_z < z) {
        z = cap_z;
        changed = true;
      }
    }
  }
  if (changed) {
    write_mesh();
  }
}

void VirtualSheet::reset() {
  std::fill(elastic_z_.begin(), elastic_z_.end(), 0.0);
  std::fill(surface_z_.begin(), surface_z_.end(), 0.0);
  write_mesh();
}

// haptic path: 256 nodes by default, cheaper than tracking which ones changed.
void VirtualSheet::write_mesh() {
  TriangleMesh& mesh = *mesh_;
  const auto at = [this](int i, int j) { return surface_z_[static_cast<std::size_t>(j * n_ + i)]; };
  for (int j = 0; j < n_; ++j) {
    for (int i = 0; i < n_; ++i) {
      const std::size_t v = static_cast<std::size_t>(j * n_ + i);
      mesh.vertices[v].z() = surface_z_[v];
      // Height-field normal (−∂z/∂x, −∂z/∂y, 1) by central differences, one-sided at borders.
      const int i0 = std::max(i - 1, 0), i1 = std::min(i + 1, n_ - 1);
      const int j0 = std::max(j - 1, 0), j1 = std::min(j + 1, n_ - 1);
      const double dzdx = (at(i1, j) - at(i0, j)) / ((i1 - i0) * spacing_m_);
      const double dzdy = (at(i, j1) - at(i, j0)) / ((j1 - j0) * spacing_m_);
      mesh.vertex_normals[v] = Vec3(-dzdx, -dzdy, 1.0).normalized();
    }
  }
}

namespace {

/// Grid cell (i, j) and barycentric-ish offsets (u, v) ∈ [0,1]² of a clamped planar point.
struct CellPos {
  int i, j;
  double u, v;
};

CellPos locate(double x_m, double y_m, double side_m, double spacing_m, int n) {
  const double half = 0.5 * side_m;
  const double fx = std::clamp((x_m + half) / spacing_m, 0.0, static_cast<double>(n - 1));
  const double fy = std::clamp((y_m + half) / spacing_m, 0.0, static_cast<double>(n - 1));
  const int i = std::min(static_cast<int>(fx), n - 2);
  const int j = std::min(static_cast<int>(fy), n - 2);
  return {i, j, fx - i, fy - j};
}

}  // namespace

// haptic path
double VirtualSheet::height_at(double x_m, double y_m, SheetLayer layer) const {
  const std::vector<double>& z = field(layer);
  if (std::isnan(x_m) || std::isnan(y_m)) {
    return 0.0;
  }
  const CellPos c = locate(x_m, y_m, side_m_, spacing_m_, n_);
  const auto at = [&](int i, int j) { return z[static_cast<std::size_t>(j * n_ + i)]; };
  const double z00 = at(c.i, c.j), z10 = at(c.i + 1, c.j);
  const double z01 = at(c.i, c.j + 1), z11 = at(c.i + 1, c.j + 1);
  // Same split as make_sheet: diagonal (i,j)–(i+1,j+1).
  if (c.u >= c.v) {
    return z00 + c.u * (z10 - z00) + c.v * (z11 - z10);
  }
  return z00 + c.v * (z01 - z00) + c.u * (z11 - z01);
}

// haptic path
Vec3 VirtualSheet::normal_at(double x_m, double y_m, SheetLayer layer) const {
  const std::vector<double>& z = field(layer);
  if (std::isnan(x_m) || std::isnan(y_m)) {
    return Vec3::UnitZ();
  }
  const CellPos c = locate(x_m, y_m, side_m_, spacing_m_, n_);
  const auto at = [&](int i, int j) { return z[static_cast<std::size_t>(j * n_ + i)]; };
  const double z00 = at(c.i, c.j), z10 = at(c.i + 1, c.j);
  const double z01 = at(c.i, c.j + 1), z11 = at(c.i + 1, c.j + 1);
  if (c.u >= c.v) {
    return Vec3(-(z10 - z00), -(z11 - z10), spacing_m_).normalized();
  }
  return Vec3(-(z11 - z01), -(z01 - z00), spacing_m_).normalized();
}

// haptic path
SheetSphereContact VirtualSheet::sphere_contact(const Vec3& center_sheet, double radius_m,
                                                SheetLayer layer) const {
  SheetSphereContact out;
  if (!finite3(center_sheet) || !std::isfinite(radius_m) || radius_m < 0.0) {
    return out;
  }
  const std::vector<double>& z = field(layer);
  const double half = 0.5 * side_m_;
  const double cx = center_sheet.x(), cy = center_sheet.y();
  const bool over_square = std::abs(cx) <= half && std::abs(cy) <= half;
  const bool below = over_square && center_sheet.z() < height_at(cx, cy, layer);

  // Cells whose planar extent meets the sphere's planar footprint. A centre that fell below the
  // sheet may be far from it; then the cell under the centre is still searched.
  double reach_m = radius_m;
  if (below) {
    reach_m = std::max(reach_m, height_at(cx, cy, layer) - center_sheet.z());
  }
  const auto cell_range = [&](double c, int& lo, int& hi) {
    const double lo_f = std::floor((c - reach_m + half) / spacing_m_);
    const double hi_f = std::floor((c + reach_m + half) / spacing_m_);
    lo = static_cast<int>(std::clamp(lo_f, 0.0, static_cast<double>(n_ - 1)));
    hi = static_cast<int>(std::clamp(hi_f, -1.0, static_cast<double>(n_ - 2)));
  };
  if (cx + reach_m < -half || cx - reach_m > half || cy + reach_m < -half || cy - reach_m > half) {
    return out;
  }
  int i_lo = 0, i_hi = 0, j_lo = 0, j_hi = 0;
  cell_range(cx, i_lo, i_hi);
  cell_range(cy, j_lo, j_hi);

  const auto node = [&](int i, int j) {
    return Vec3(-half + i * spacing_m_, -half + j * spacing_m_,
                z[static_cast<std::size_t>(j * n_ + i)]);
  };
  double best_d2 = kInf;
  Vec3 best_p = Vec3::Zero();
  for (int j = j_lo; j <= j_hi; ++j) {
    for (int i = i_lo; i <= i_hi; ++i) {
      const Vec3 a = node(i, j), b = node(i + 1, j), c = node(i + 1, j + 1), d = node(i, j + 1);
      const TriangleClosest t0 = closest_point_on_triangle(center_sheet, a, b, c);
      if (t0.distance_sq < best_d2) {
        best_d2 = t0.distance_sq;
        best_p = t0.point;
      }
      const TriangleClosest t1 = closest_point_on_triangle(center_sheet, a, c, d);
      if (t1.distance_sq < best_d2) {
        best_d2 = t1.distance_sq;
        best_p = t1.point;
      }
    }
  }
  if (!std::isfinite(best_d2)) {
    return out;
  }
  const double dist_m = std::sqrt(best_d2);
  const double penetration_m = below ? radius_m + dist_m : radius_m - dist_m;
  if (penetration_m <= 0.0) {
    return out;
  }
  out.touching = true;
  out.penetration_m = penetration_m;
  out.p_sheet = best_p;
  // Below tiny distances the direction is noise; the face normal is the right push direction.
  if (dist_m > 1e-12) {
    out.normal_sheet =
        below ? Vec3((best_p - center_sheet) / dist_m) : Vec3((center_sheet - best_p) / dist_m);
  } else {
    out.normal_sheet = normal_at(best_p.x(), best_p.y(), layer);
  }
  return out;
}

double VirtualSheet::max_depth_m() const {
  const double lowest = *std::min_element(surface_z_.begin(), surface_z_.end());
  return std::max(-lowest, 0.0);
}

}  // namespace hapsim
