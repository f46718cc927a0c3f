// The virtual sheet (seed 000 §3.2.2, after Hirota & Hirose): an N×N height grid over a square of
// side L, centred at the origin of its own frame, z up, rest surface z = 0. Each cycle the forces
// pressing on it are summed through a replaceable profile (Gaussian by default), and rigid spheres
// resting on it transcribe their lower cap into it.
//
// Two height fields are kept:
//  * elastic  — the sum of the profile over this cycle's contacts (what the forces produce);
//  * surface  — what is shown and collided with: min(elastic, every imprinted sphere's cap).
// The split exists because an imprinting sphere lies exactly on its own imprint: pressing the
// surface it would feel no penetration and sink. So contacts press the elastic field (in the world
// every contact does, tools and bodies alike: deform/sheet_query.h), and the surface, imprints
// included, is what is shown.
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/deform/sheet_profile.h"
#include "hapsim/geometry/triangle_mesh.h"

#include <cstddef>
#include <memory>
#include <span>
#include <vector>

namespace hapsim {

struct VirtualSheetOptions {
  /// Grid nodes per side (the paper's 16); ≥ 2.
  int nodes_per_side = 16;
  /// Side of the square, metres. Not in the paper; 0.2 m puts ~3 nodes inside d0 = 44 mm.
  double side_m = 0.2;
  /// Deepest the elastic field may go below rest (metres, > 0); guards against huge forces.
  double max_depth_m = kInf;
};

/// One force pressing on the sheet this cycle.
struct SheetContact {
  /// Contact point in the sheet frame; only x and y are used.
  Vec3 p_sheet = Vec3::Zero();
  /// Magnitude of the force pushing into the sheet (along −z), newtons. Negative values are
  /// clamped to 0 (a pushing contact cannot pull the sheet up).
  double force_n = 0.0;
};

/// Which height field a query reads.
enum class SheetLayer : std::uint8_t { kSurface, kElastic };

/// Result of a sphere-vs-sheet query.
struct SheetSphereContact {
  bool touching = false;
  /// How far the sphere overlaps the sheet along `normal_sheet`, metres (> 0 when touching).
  double penetration_m = 0.0;
  /// Unit direction to push the sphere out of the sheet (sheet frame).
  Vec3 normal_sheet = Vec3::UnitZ();
  /// Closest point on the sheet to the sphere's centre (sheet frame).
  Vec3 p_sheet = Vec3::Zero();
};

class VirtualSheet {
 public:
  /// Throws hapsim::Error on N < 2, non-positive or non-finite side/max depth. `profile` null →
  /// GaussianSheetProfile with the paper's defaults.
  explicit VirtualSheet(VirtualSheetOptions options = {},
                        std::unique_ptr<const SheetProfile> profile = nullptr);

  VirtualSheet(VirtualSheet&&) noexcept = default;
  VirtualSheet& operator=(VirtualSheet&&) noexcept = default;
  VirtualSheet(const VirtualSheet&) = delete;
  VirtualSheet& operator=(const VirtualSheet&) = delete;
  ~VirtualSheet() = default;

  /// Replaces this cycle's displacement: elastic = Σ profile over `contacts`, and the surface
  /// becomes the elastic field (earlier imprints are cleared; imprint again after this call).
  /// Contacts with a non-finite point or force are skipped and counted in rejected_contacts().
  /// haptic path
  void apply_contacts(std::span<const SheetContact> contacts);

  /// Transcribes a sphere (centre in the sheet frame, radius in metres) into the surface: every
  /// node under it is lowered to the sphere's lower cap where the cap is below the current surface,
  /// z = min(z, c.z − sqrt(R² − d²)). Leaves the elastic field alone. Non-finite input or a
  /// negative radius is ignored and counted. haptic path
  void imprint_sphere(const Vec3& center_sheet, double radius_m);

  /// Back to the flat rest state.
  void reset();

  /// Height of the chosen field at (x, y) by the same triangle interpolation as the mesh; (x, y)
  /// outside the square are clamped to its border. haptic path
  [[nodiscard]] double height_at(double x_m, double y_m,
                                 SheetLayer layer = SheetLayer::kSurface) const;
  /// Upward unit normal of the triangle under (x, y) (clamped like height_at). haptic path
  [[nodiscard]] Vec3 normal_at(double x_m, double y_m,
                               SheetLayer layer = SheetLayer::kSurface) const;

  /// Sphere vs the chosen field: exact closest point over the grid triangles under the sphere.
  /// A centre above the field is outside (penetration = R − distance); a centre below it, within
  /// the square, has passed through (penetration = R + distance, normal still points up-and-out).
  /// haptic path
  [[nodiscard]] SheetSphereContact sphere_contact(const Vec3& center_sheet, double radius_m,
                                                  SheetLayer layer = SheetLayer::kSurface) const;

  /// The surface as a mesh (make_sheet topology: node (i, j) is vertex j·N + i at
  /// x = −L/2 + i·L/(N−1)); vertex z and vertex normals are updated in place, the addresses of
  /// the mesh and its arrays never change, so collision structures can hold it and refit.
  [[nodiscard]] const TriangleMesh& mesh() const { return *mesh_; }
  [[nodiscard]] int nodes_per_side() const { return n_; }
  [[nodiscard]] double side_m() const { return side_m_; }
  [[nodiscard]] double spacing_m() const { return spacing_m_; }
  [[nodiscard]] const SheetProfile& profile() const { return *profile_; }
  /// Node heights, row-major (j·N + i).
  [[nodiscard]] std::span<const double> surface_heights() const { return surface_z_; }
  [[nodiscard]] std::span<const double> elastic_heights() const { return elastic_z_; }
  /// Deepest point of the surface below rest, metres (≥ 0).
  [[nodiscard]] double max_depth_m() const;
  /// Contacts/imprints skipped since construction because of non-finite or invalid input.
  [[nodiscard]] std::size_t rejected_contacts() const { return rejected_; }

 private:
  [[nodiscard]] const std::vector<double>& field(SheetLayer layer) const {
    return layer == SheetLayer::kElastic ? elastic_z_ : surface_z_;
  }
  /// Index range [lo, hi] of nodes whose coordinate lies within `radius` of `c`, clamped.
  void node_range(double c, double radius, int& lo, int& hi) const;
  void write_mesh();

  int n_;
  double side_m_;
  double spacing_m_;
  double max_depth_m_;
  std::unique_ptr<const SheetProfile> profile_;
  std::vector<double> elastic_z_;
  std::vector<double> surface_z_;
  std::unique_ptr<TriangleMesh> mesh_;
  std::size_t rejected_ = 0;
};

}  // namespace hapsim
