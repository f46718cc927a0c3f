// The displacement profile of the virtual sheet (seed 000 §3.2.2, after Hirota & Hirose): how far
// a grid node sinks at planar distance d from a contact that pushes with force F. Replaceable so
// a scene can change the sheet's "transformation characteristics" (the paper's words) without
// touching the grid code.
#pragma once

namespace hapsim {

class SheetProfile {
 public:
  virtual ~SheetProfile() = default;

  /// Depth (metres, ≥ 0, downwards) of a node at planar distance `distance_m` (≥ 0) from a
  /// contact pushing into the sheet with `force_n` (≥ 0, finite). Must be 0 for
  /// distance_m ≥ influence_radius_m(): the sheet only visits nodes inside that radius.
  /// haptic path: called once per affected node per contact; must not allocate.
  [[nodiscard]] virtual double depth_m(double distance_m, double force_n) const = 0;

  /// Planar radius beyond which depth_m() is zero (metres, > 0, finite).
  [[nodiscard]] virtual double influence_radius_m() const = 0;
};

/// Parameters of the Gaussian profile in SI units.
struct GaussianSheetParams {
  /// d0: largest planar distance the force influences.
  double cutoff_radius_m = 0.044;
  /// ξ: width of the Gaussian ("acuteness of transformation").
  double width_m = 0.0401;
  /// F0: force per unit depth. The paper's 3.0 N/mm is 3000 N/m.
  double sensitivity_n_per_m = 3000.0;

  /// The paper's units (mm, N/mm), converted at the edge.
  static GaussianSheetParams from_mm(double cutoff_radius_mm, double width_mm,
                                     double sensitivity_n_per_mm) {
    return {cutoff_radius_mm * 1e-3, width_mm * 1e-3, sensitivity_n_per_mm * 1e3};
  }
};

/// z(d) = (F/F0)·(exp(−(d/ξ)²) − exp(−(d0/ξ)²)) for d < d0, else 0 — zero at d0 so the
/// surface is continuous where the influence ends. With F in N and F0 in N/m, F/F0 is metres
/// (the paper's F/F0 with F0 in N/mm is millimetres; same physical depth).
class GaussianSheetProfile final : public SheetProfile {
 public:
  /// Throws hapsim::Error unless every parameter is finite and > 0.
  explicit GaussianSheetProfile(GaussianSheetParams params = {});

  [[nodiscard]] double depth_m(double distance_m, double force_n) const override;
  [[nodiscard]] double influence_radius_m() const override { return params_.cutoff_radius_m; }
  [[nodiscard]] const GaussianSheetParams& params() const { return params_; }

 private:
  GaussianSheetParams params_;
  double inv_width_sq_per_m2_;
  /// exp(−(d0/ξ)²), subtracted so the profile ends at zero.
  double tail_;
};

}  // namespace hapsim
