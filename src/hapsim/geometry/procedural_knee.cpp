#include "hapsim/geometry/procedural_knee.h"

#include "hapsim/core/error.h"
#include "hapsim/geometry/csg.h"
#include "hapsim/geometry/polygonizer.h"

#include <cmath>

namespace hapsim {
namespace {

// Dimensions (metres) of an adult knee, rounded: femoral condyles ~45 mm wide each side of the
// notch, tibial plateau ~75 mm across, patella ~40 mm, thigh and calf ~110 mm across under the
// skin. The model is the knee region: bones stop 120 mm from the joint line, the skin 130 mm.
constexpr double kBoneEnd = 0.12;
constexpr double kSkinEnd = 0.13;

Iso3 at(double x, double y, double z) {
  return Iso3(Eigen::Translation3d(x, y, z));
}

// A capped cylinder between heights z0 < z1 on the axis through (x, y).
CsgSolid column(double radius, double x, double y, double z0, double z1) {
  return CsgSolid::cylinder(radius, 0.5 * (z1 - z0)).transformed(at(x, y, 0.5 * (z0 + z1)));
}

// A frustum with radius r0 at z0 and r1 at z1 (z0 < z1) on the axis through (x, y).
CsgSolid taper(double r0, double r1, double x, double y, double z0, double z1) {
  return CsgSolid::frustum(r0, r1, 0.5 * (z1 - z0)).transformed(at(x, y, 0.5 * (z0 + z1)));
}

CsgSolid ball(double radius, double x, double y, double z) {
  return CsgSolid::sphere(radius).transformed(at(x, y, z));
}

CsgSolid box(double hx, double hy, double hz, double x, double y, double z) {
  return CsgSolid::block(Vec3(hx, hy, hz)).transformed(at(x, y, z));
}

CsgSolid femur() {
  const CsgSolid shaft = column(0.014, 0.0, 0.0, 0.06, kBoneEnd);
  const CsgSolid metaphysis = taper(0.030, 0.014, 0.0, 0.0, 0.030, 0.075);
  // Two condyles, rounded below, with the intercondylar notch between them at the back.
  const CsgSolid condyles = ball(0.022, -0.021, -0.004, 0.025) | ball(0.022, 0.021, -0.004, 0.025);
  const CsgSolid notch = box(0.007, 0.02, 0.012, 0.0, -0.022, 0.012);
  return (shaft | metaphysis | condyles) - notch;
}

CsgSolid tibia() {
  const CsgSolid plateau = column(0.038, 0.0, 0.0, -0.020, -0.004);
  const CsgSolid metaphysis = taper(0.014, 0.035, 0.0, 0.0, -0.075, -0.020);
  const CsgSolid shaft = column(0.014, 0.0, 0.0, -kBoneEnd, -0.07);
  const CsgSolid tuberosity = ball(0.012, 0.0, 0.030, -0.035);
  return plateau | metaphysis | shaft | tuberosity;
}

CsgSolid fibula() {
  return ball(0.009, 0.035, -0.023, -0.045) | column(0.0075, 0.035, -0.023, -kBoneEnd, -0.045);
}

// A lens-shaped patella, 38 mm across: a sphere cut to a 14 mm slab facing forward.
CsgSolid patella() {
  return ball(0.019, 0.0, 0.042, 0.035) & box(0.03, 0.007, 0.03, 0.0, 0.042, 0.035);
}

// The front of the thigh above the patella: a sector of a cylinder around the femur.
CsgSolid quadriceps() {
  return column(0.050, 0.0, 0.0, 0.062, kBoneEnd) & box(0.06, 0.02, 0.1, 0.0, 0.042, 0.1);
}

// The back of the thigh.
CsgSolid hamstrings() {
  return column(0.050, 0.0, 0.0, 0.0505, kBoneEnd) & box(0.06, 0.02, 0.1, 0.0, -0.042, 0.1);
}

// Two heads of the calf muscle behind the tibia, each a tapered column with rounded ends.
CsgSolid gastrocnemius() {
  CsgSolid out;
  for (const double x : {-0.018, 0.018}) {
    out = out | taper(0.010, 0.016, x, -0.055, -0.11, -0.03) | ball(0.016, x, -0.055, -0.03) |
          ball(0.010, x, -0.055, -0.11);
  }
  return out;
}

// Thin parts are built kThin times thicker about their own centre and squashed back after
// polygonising (an affine map keeps a closed mesh closed and its orientation): cells as coarse as
// the part's width allows, not its thickness.
constexpr double kThin = 4.0;

// From the patella's lower pole to the tibial tuberosity, in front of the plateau: 5 mm thick.
CsgSolid patellar_tendon() {
  return CsgSolid::block(Vec3(0.011, 0.0025 * kThin, 0.030));
}
const Vec3 kTendonCentre(0.0, 0.044, -0.010);

// Straps along the sides of the joint, 4 mm thick; medial at -x, lateral at +x (to the fibula).
CsgSolid medial_collateral_ligament() {
  return CsgSolid::block(Vec3(0.002 * kThin, 0.008, 0.035));
}
const Vec3 kMclCentre(-0.0465, -0.002, 0.0);
CsgSolid lateral_collateral_ligament() {
  return CsgSolid::block(Vec3(0.002 * kThin, 0.006, 0.038));
}
const Vec3 kLclCentre(0.0465, -0.012, -0.008);

// Everything under a closed skin: the limb cylinder (6 mm over the patella's front) and the calf
// bulge (5 mm over the gastrocnemius).
CsgSolid skin() {
  CsgSolid calf;
  for (const double x : {-0.018, 0.018}) {
    calf = calf | taper(0.015, 0.021, x, -0.055, -0.11, -0.03) | ball(0.021, x, -0.055, -0.03) |
           ball(0.015, x, -0.055, -0.11);
  }
  return column(0.055, 0.0, 0.0, -kSkinEnd, kSkinEnd) | calf;
}

struct PartSpec {
  const char* name;
  TissueKind tissue;
  CsgSolid (*solid)();
  double cell_m;               // polygoniser cell at resolution_scale 1
  Vec3 squash = Vec3::Ones();  // applied to the polygonised vertices, then...
  Vec3 centre = Vec3::Zero();  // ...moved here
};

}  // namespace

std::string_view tissue_kind_name(TissueKind kind) {
  switch (kind) {
    case TissueKind::kBone:
      return "bone";
    case TissueKind::kCartilage:
      return "cartilage";
    case TissueKind::kMuscle:
      return "muscle";
    case TissueKind::kTendon:
      return "tendon";
    case TissueKind::kLigament:
      return "ligament";
    case TissueKind::kSkin:
      return "skin";
  }
  return "unknown";
}

std::vector<KneePart> make_procedural_knee(const ProceduralKneeOptions& options) {
  if (!(options.resolution_scale > 0.0) || !std::isfinite(options.resolution_scale)) {
    throw Error("procedural knee", "resolution_scale must be a finite number > 0");
  }
  // Cells sized so the whole knee has about 13.5k vertices; thin parts get finer cells so they
  // stay closed (a part must be at least two cells thick).
  const PartSpec specs[] = {
      {"femur", TissueKind::kBone, femur, 0.0072},
      {"tibia", TissueKind::kBone, tibia, 0.0072},
      {"fibula", TissueKind::kBone, fibula, 0.0040},
      {"patella", TissueKind::kBone, patella, 0.0045},
      {"quadriceps", TissueKind::kMuscle, quadriceps, 0.0080},
      {"hamstrings", TissueKind::kMuscle, hamstrings, 0.0080},
      {"gastrocnemius", TissueKind::kMuscle, gastrocnemius, 0.0072},
      {"patellar_tendon", TissueKind::kTendon, patellar_tendon, 0.0042, Vec3(1.0, 1.0 / kThin, 1.0),
       kTendonCentre},
      {"medial_collateral_ligament", TissueKind::kLigament, medial_collateral_ligament, 0.0042,
       Vec3(1.0 / kThin, 1.0, 1.0), kMclCentre},
      {"lateral_collateral_ligament", TissueKind::kLigament, lateral_collateral_ligament, 0.0042,
       Vec3(1.0 / kThin, 1.0, 1.0), kLclCentre},
      {"skin", TissueKind::kSkin, skin, 0.0115},
  };
  std::vector<KneePart> parts;
  for (const PartSpec& spec : specs) {
    if (spec.tissue == TissueKind::kSkin && !options.include_skin) {
      continue;
    }
    PolygonizeOptions po;
    po.cell_size_m = spec.cell_m / options.resolution_scale;
    KneePart part;
    part.name = spec.name;
    part.tissue = spec.tissue;
    const CsgSolid solid = spec.solid();
    // A flat face that falls on grid nodes makes zero-area triangles (several edge crossings
    // meet at the node): try a slightly larger cell until none are left. Deterministic.
    for (int attempt = 0;; ++attempt) {
      PolygonizeStats stats;
      part.mesh = polygonize(solid, po, &stats);
      if (stats.degenerate_triangles == 0 || attempt == 8) {
        break;
      }
      po.cell_size_m *= 1.013;
    }
    if (spec.squash != Vec3::Ones() || spec.centre != Vec3::Zero()) {
      for (Vec3& v : part.mesh.vertices) {
        v = spec.centre + spec.squash.cwiseProduct(v);
      }
      part.mesh.compute_vertex_normals();
    }
    parts.push_back(std::move(part));
  }
  return parts;
}

}  // namespace hapsim
