// A procedurally generated left knee for the palpation scene (architecture.md#scenes; Burdea et al. 1994 used a
// ~13.5k-vertex model): bones, muscles, tendon, collateral ligaments and a skin layer, each its own
// closed mesh built from CSG solids and polygonised. Deterministic: same options, same meshes.
//
// Frame (metres): origin at the joint line centre, +z up the thigh (femur above, tibia below),
// +y anterior (the patella is at +y), +x lateral (the fibula is at +x).
#pragma once

#include "hapsim/geometry/triangle_mesh.h"

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace hapsim {

/// Tissue classes: a scene gives each its material (bone stiff and thin-skinned, muscle soft).
enum class TissueKind : std::uint8_t { kBone, kCartilage, kMuscle, kTendon, kLigament, kSkin };

/// "bone", "cartilage", "muscle", "tendon", "ligament", "skin".
[[nodiscard]] std::string_view tissue_kind_name(TissueKind kind);

struct KneePart {
  /// femur, tibia, fibula, patella, quadriceps, hamstrings, gastrocnemius, patellar_tendon,
  /// medial_collateral_ligament, lateral_collateral_ligament, skin.
  std::string name;
  TissueKind tissue = TissueKind::kBone;
  /// Closed, outward-oriented, manifold; metres, knee frame.
  TriangleMesh mesh;
};

struct ProceduralKneeOptions {
  /// Scales the polygoniser resolution: 1 gives about 13.5k vertices in all; 2 about 4x.
  double resolution_scale = 1.0;
  /// The skin layer: encloses every other part, 3-6 mm over the patella.
  bool include_skin = true;
};

/// The parts in the order listed at KneePart::name (skin last). Parts do not intersect each other
/// except where tissues attach (tendon to patella and tibia, ligaments to bones).
[[nodiscard]] std::vector<KneePart> make_procedural_knee(const ProceduralKneeOptions& options = {});

}  // namespace hapsim
