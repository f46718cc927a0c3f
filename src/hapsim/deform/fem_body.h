// A volumetric FEM body (SPEC §12, architecture.md#deformation): linear tetrahedra, linear or
// corotational elasticity (each element's rotation from the polar decomposition of its deformation
// gradient, Müller & Gross 2004), backward Euler or quasi-static, Rayleigh damping, a material per
// region, fixed nodes. Solved by a supernodal sparse Cholesky factorisation written in
// fem_body.cpp (geometric nested dissection ordering; dense blocks through Eigen, MPL2; no other
// library): prefactored for the linear case; for the corotational one, conjugate gradients
// warm-started from the last step and preconditioned by the rest factorisation (in single
// precision, turned into each node's frame). Eigen's SimplicialLDLT was three times slower to
// solve at 20k tets (7–8 ms against 2.4 ms), which missed the step-rate targets.
//
// Not on the haptic path: a FemBody is stepped by its own thread at its own rate (world/ and
// runtime/ couple it to the 1 kHz cycle through the local contact model). Not thread-safe: one
// thread owns it. Construction may allocate and factor; step() reuses its buffers.
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/geometry/tet_mesh.h"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

namespace hapsim {

/// Isotropic elastic material of one region.
struct FemMaterial {
  /// Young's modulus E, Pa (soft tissue: 1e3–1e5; cartilage ~1e6).
  double youngs_modulus_pa = 10e3;
  /// Poisson ratio ν in [0, 0.5) (nearly incompressible tissue: 0.45–0.49).
  double poisson_ratio = 0.45;
  double density_kg_per_m3 = 1000.0;
  /// Rayleigh damping C = α·M + β·K: α (1/s) and β (s).
  double rayleigh_mass_per_s = 0.0;
  double rayleigh_stiffness_s = 0.0;
  /// Strain stiffening under a contact, Pa: Zheng & Mak's (1999) nonlinear factor E₁ of the
  /// in-vivo modulus E(ε) = E₀ + E₁·ε, ε the indentation over the tissue's thickness there, E₀
  /// `youngs_modulus_pa`. The elastic law stays linear (prefactored); the coupling applies it to
  /// each contact's load–indentation (world/fem_coupling.h). 0: no stiffening.
  double nonlinear_modulus_pa = 0.0;
};

/// Which material a region (TetMesh::regions value) gets.
struct FemRegionMaterial {
  std::int32_t region = 0;
  FemMaterial material;
};

enum class FemElasticity : std::uint8_t {
  kLinear,        ///< small-strain linear elasticity: fast, prefactored, wrong under rotation
  kCorotational,  ///< linear in each element's rotated frame: right under large rotations
};

enum class FemIntegration : std::uint8_t {
  kBackwardEuler,  ///< implicit dynamics: (M + dt·C + dt²·K)·Δv = dt·(f − K·u − C·v)
  kQuasiStatic,    ///< equilibrium each step: K·u = f (no mass, no damping)
};

[[nodiscard]] std::string_view to_string(FemElasticity elasticity);
[[nodiscard]] std::string_view to_string(FemIntegration integration);

struct FemOptions {
  FemElasticity elasticity = FemElasticity::kCorotational;
  FemIntegration integration = FemIntegration::kBackwardEuler;
  /// Step length, s (the FEM thread's period).
  double dt_s = 0.01;
  /// Body force per unit mass, mesh frame (zero: the tissue's rest shape already carries its
  /// weight, as a meshed scan does).
  Vec3 gravity_m_per_s2 = Vec3::Zero();
  /// Conjugate gradients (corotational): at most this many iterations a solve, stopping when the
  /// residual is below this fraction of the size of the forces in the right-hand side (the
  /// larger of its norm and ‖M·v‖ + dt·(‖f_ext + f_g‖ + ‖f_el‖), dt and M·v dropped
  /// quasi-statically: those forces cancel at equilibrium, where a fraction of their sum would
  /// ask for ever more accuracy). solve_static (corotational) stops its rotation updates when
  /// one moves the nodes by less than 100 times this fraction of their displacement.
  int max_cg_iterations = 200;
  /// 1e-5: a fingertip's 6 mm dent in a 20k-tet block moves 30 nm from where 1e-8 puts it, in
  /// half the CG iterations (12 against 22 a step).
  double cg_relative_tolerance = 1e-5;
  /// Quasi-static corotational: rotation updates per step (each one CG solve).
  int quasi_static_iterations = 4;
};

/// One external force on one node (mesh frame, N).
struct FemNodeForce {
  std::uint32_t node = 0;
  Vec3 force_n = Vec3::Zero();
};

/// A point of the body as a weighted sum of nodes (a contact patch, a barycentric surface point):
/// its displacement is Σ wᵢ·uᵢ, and a force F on it loads node i with wᵢ·F. Weights sum to 1.
struct FemNodeWeight {
  std::uint32_t node = 0;
  double weight = 0.0;
};

struct FemStepStats {
  int cg_iterations = 0;           ///< summed over the step's solves (0 for a direct solve)
  double residual_relative = 0.0;  ///< the last CG solve's, relative as in cg_relative_tolerance
  bool converged = true;
  double solve_ms = 0.0;
};

struct FemSphereContactResult {
  /// Sum of the contact forces on the sphere, mesh frame, N (pushes the sphere out).
  Vec3 force_on_sphere_n = Vec3::Zero();
  std::size_t contact_nodes = 0;
  int active_set_iterations = 0;
  bool converged = false;
};

class FemBody {
 public:
  /// Builds element matrices, the mass, and (for the linear case and as the corotational
  /// preconditioner) factors the system with the fixed nodes' rows and columns removed. Throws
  /// hapsim::Error(source, ...) for an invalid mesh (validate_tet_mesh), a region with no material
  /// (naming the region and the first element in it), a material out of range (E ≤ 0, ν outside
  /// [0, 0.5), density ≤ 0, negative damping, non-finite), a fixed node out of range, no fixed
  /// node (a free body is singular under quasi-static loads: refused), or a failed factorisation
  /// (naming a node: K is singular when the fixed nodes do not hold every piece, e.g. a single
  /// fixed node). Also refused: two materials for one region, dt ≤ 0, a CG tolerance outside
  /// (0, 1), fewer than one CG or quasi-static iteration. A node in no tet stays where it is.
  FemBody(TetMesh mesh, const std::vector<FemRegionMaterial>& materials,
          std::vector<std::uint32_t> fixed_nodes, const FemOptions& options,
          std::string_view source = "fem body");
  ~FemBody();
  FemBody(const FemBody&) = delete;
  FemBody& operator=(const FemBody&) = delete;
  FemBody(FemBody&&) noexcept;
  FemBody& operator=(FemBody&&) noexcept;

  [[nodiscard]] const TetMesh& rest_mesh() const;
  [[nodiscard]] const FemOptions& options() const;
  [[nodiscard]] std::size_t node_count() const;
  [[nodiscard]] std::size_t tet_count() const;
  [[nodiscard]] bool is_fixed(std::uint32_t node) const;
  /// The fixed nodes, ascending and without duplicates: the order set_fixed_positions expects.
  [[nodiscard]] const std::vector<std::uint32_t>& fixed_nodes() const;
  /// Current node positions and velocities, mesh frame.
  [[nodiscard]] const std::vector<Vec3>& positions() const;
  [[nodiscard]] const std::vector<Vec3>& velocities() const;
  [[nodiscard]] Vec3 displacement(std::uint32_t node) const;

  /// Replaces the external loads (nodal forces, N, mesh frame) until the next call. Forces on
  /// fixed nodes are ignored (the support takes them). Non-finite forces are ignored and counted.
  void set_loads(std::span<const FemNodeForce> loads);
  /// Loads dropped for being non-finite or naming no node, since construction.
  [[nodiscard]] std::size_t rejected_loads() const;

  /// Moves the fixed nodes (a bone that moved, a prescribed displacement): one position per
  /// entry of fixed_nodes(), mesh frame. The free nodes follow at the next step or solve; the
  /// move is a jump (the fixed nodes carry no velocity into the damping). Throws hapsim::Error,
  /// changing nothing, for a wrong count or a non-finite position.
  void set_fixed_positions(std::span<const Vec3> positions);
  /// Sets every node's position and velocity (a recorded state, a rigid motion): the fixed
  /// nodes' positions become their held positions and their velocities are ignored (zero);
  /// empty `velocities` means all zero. The element rotations are recomputed from scratch.
  /// Throws hapsim::Error, changing nothing, for a wrong size or a non-finite value.
  void set_state(std::span<const Vec3> positions, std::span<const Vec3> velocities = {});

  /// One step of options().dt_s under the current loads (backward Euler or quasi-static).
  FemStepStats step();
  /// Static equilibrium under the current loads (velocities zeroed): exact for the linear case,
  /// iterated on the rotations for the corotational one (each round a CG solve with the
  /// rotations held, then a line search on the energy along it; until the update is below the
  /// tolerance, cg_relative_tolerance, at most 100 rounds; `converged` says whether it got there).
  FemStepStats solve_static();
  /// Back to rest: positions = rest (the fixed nodes' too), velocities = 0, loads cleared.
  void reset();

  /// The tissue's own compliance at a point, along a direction: nᵀ·H·K⁻¹·Hᵀ·n (m/N), H the
  /// point's node weights (Duriez et al. 2006's condensed compliance, for one contact). The
  /// quasi-static stiffness K: the linear one, or the corotational one at the current rotations
  /// (computed with the rest factorisation in the frame of each weighted node, the rotation
  /// nearest the mean of its tets' rotations: exact for a rigidly rotated body, first-order
  /// otherwise). One back-substitution; allocates nothing. Fixed nodes, nodes out of range and
  /// non-finite weights contribute nothing (0 when nothing is left).
  [[nodiscard]] double compliance_along(std::span<const FemNodeWeight> point, const Vec3& n);

  /// Quasi-static contact with a rigid sphere (centre and radius, mesh frame), frictionless:
  /// free boundary nodes inside the sphere are held on its surface along its normal by penalty
  /// springs of `penalty_n_per_m` each, the active set updated until it no longer changes (at
  /// most 30 rounds; each a Newton step with a line search on the energy, which keeps the set
  /// from oscillating). Changes the body's state to the equilibrium found (loads kept,
  /// velocities zeroed). Not for the haptic rate: it factors K plus the springs (again when a
  /// quarter of the set changed). Throws hapsim::Error for a non-finite centre, a radius or
  /// penalty ≤ 0.
  FemSphereContactResult solve_static_sphere_contact(const Vec3& center, double radius_m,
                                                     double penalty_n_per_m = 1e5);

  /// Elastic (internal) force on every node at the current positions, N: −∂(elastic energy)/∂x
  /// (corotational: −Σ Rₑ·Kₑ·(Rₑᵀ·xₑ − Xₑ)). Zero for a rigidly moved body with the
  /// corotational model; not zero with the linear one.
  void elastic_forces(std::vector<Vec3>& out) const;
  /// Per tetrahedron, the von Mises stress of its (rotated) linear strain, Pa.
  void von_mises_pa(std::vector<double>& out) const;
  /// Per tetrahedron, the Cauchy stress (symmetric, mesh frame), Pa.
  void element_stress_pa(std::vector<Mat3>& out) const;
  [[nodiscard]] double elastic_energy_j() const;
  [[nodiscard]] double kinetic_energy_j() const;
  [[nodiscard]] double total_mass_kg() const;

  /// The factorisation: the nonzeros of one factor (its lower triangle, the supernodes' explicit
  /// zeros included; every factor here shares that pattern), the bytes of all the factors held
  /// (backward Euler: M + dt·C + dt²·K and K, the former in single precision when corotational;
  /// quasi-static: K, plus a single-precision copy when corotational; after a sphere contact, its
  /// own), the construction's factorisation time (ms, both factors), and the unknowns (3 per free
  /// node).
  [[nodiscard]] std::size_t factor_nonzeros() const;
  [[nodiscard]] std::size_t factor_memory_bytes() const;
  [[nodiscard]] double factorisation_ms() const;
  [[nodiscard]] std::size_t unknowns() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hapsim
