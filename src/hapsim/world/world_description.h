// What a world is made of, as plain read-only data: materials, bodies split into segments (each
// with its own mesh and material), and tools. A scene file is parsed into this (scene/), tests
// and programs may fill it in code; World (world.h) builds its query structures from it once and
// never changes it, so a step only touches per-step state.
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/deform/fem_body_description.h"
#include "hapsim/deform/sheet_profile.h"
#include "hapsim/deform/vertex_deflection.h"
#include "hapsim/deform/virtual_sheet.h"
#include "hapsim/force/contact_material.h"
#include "hapsim/geometry/csg.h"
#include "hapsim/geometry/triangle_mesh.h"
#include "hapsim/kinematics/hand_model.h"
#include "hapsim/world/world_controller.h"

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace hapsim {

/// How a tool's contact with a segment turns into force.
enum class ContactResponse : std::uint8_t {
  /// God-object proxy: the tool's proxy never enters the segment (bone, ligament, tendon, thin
  /// sheets): no pop-through at any speed the device can reach.
  kProxy,
  /// Penalty spring on the tool's own position: the tool sinks in (soft tissue: skin, muscle),
  /// the force grows with depth up to the segment's maximum penetration and maximum force.
  kPenalty,
};

/// Which proximity query answers contacts with a segment.
enum class ContactMethod : std::uint8_t {
  kExact,       ///< MeshBvh: exact closest point (the reference).
  kSphereTree,  ///< SphereTree: sphere hierarchy, refined exactly.
  kKnee,        ///< KneeIndex: the knee paper's groups and plane test (approximate).
  // CSG segments ignore the method: they always use CsgQuery (SegmentDescription::csg).
};

enum class BodyKind : std::uint8_t {
  kStatic,      ///< never moves, never deforms
  kDynamic,     ///< rigid with mass: moves under gravity and its contacts (integrate stage)
  kDeformable,  ///< deforms under contact and recovers (architecture.md#deformation)
  /// Rigid, moved by a controller each step (a robot's gripper pad): pushes dynamic bodies, is
  /// never pushed.
  kKinematic,
};

/// How a deformable body deforms.
enum class BodyDeformation : std::uint8_t {
  kVertexDeflection,  ///< knee paper eq. 1 about each contact, recovering when released
  /// The virtual sheet (paper 000 §3.2.2): an N×N height grid displaced by the Gaussian profile of
  /// every force pressing it this step; a sphere resting on it transcribes its lower cap.
  kGaussianSheet,
  /// A volumetric FEM body (SPEC §12): tetrahedra, linear or corotational elasticity, on its own
  /// thread; touched through the local contact model it hands the haptic path (fem_coupling.h).
  kFem,
};

[[nodiscard]] std::string_view to_string(ContactResponse response);
[[nodiscard]] std::string_view to_string(ContactMethod method);
[[nodiscard]] std::string_view to_string(BodyKind kind);
[[nodiscard]] std::string_view to_string(BodyDeformation deformation);
/// "exact" | "spheretree" | "knee" (to_string's names); nullopt for anything else.
[[nodiscard]] std::optional<ContactMethod> parse_contact_method(std::string_view name);

struct MaterialDescription {
  std::string name;
  ContactMaterial contact;
  ContactResponse response = ContactResponse::kProxy;
  /// Used when the body is deformable.
  DeflectionParams deflection;
  /// Display only: 1 opaque, less is drawn see-through (a skin over the anatomy).
  double opacity = 1.0;
};

/// A segment that is exactly a sphere (its mesh only approximates it): bodies meet it through its
/// centre and radius, exactly, instead of through its mesh's vertices.
struct ExactSphere {
  Vec3 center_body = Vec3::Zero();
  double radius_m = 0.0;
};

struct SegmentDescription {
  std::string name;
  /// Index into WorldDescription::materials.
  std::uint32_t material = 0;
  /// In the body frame, metres. Closed and outward-oriented unless two_sided. For a CSG segment,
  /// the solid polygonised: display, sphere trees, deflection and the content hash use it.
  TriangleMesh mesh;
  /// Open surface (a sheet): both sides are outside.
  bool two_sided = false;
  /// A CSG solid (body frame) that `mesh` polygonises: contact then comes from its signed
  /// distance (CsgQuery), whatever the body's contact method.
  std::optional<CsgSolid> csg;
  /// Set when the segment is exactly this sphere (the mesh tessellates it).
  std::optional<ExactSphere> sphere;
};

/// Mass properties of a dynamic body (BodyKind::kDynamic), in its body frame.
struct RigidBodyDescription {
  double mass_kg = 0.1;
  /// Centre of mass, body frame, metres.
  Vec3 com_body = Vec3::Zero();
  /// Inertia about the centre of mass, body axes, kg·m² (symmetric positive definite).
  Mat3 inertia_kg_m2 = Mat3::Identity() * 1e-4;
  /// Velocity of the centre of mass and angular velocity at the start, world frame.
  Vec3 v_world = Vec3::Zero();
  Vec3 w_world = Vec3::Zero();
};

struct BodyDescription {
  std::string name;
  BodyKind kind = BodyKind::kStatic;
  Iso3 X_world_body = Iso3::Identity();
  ContactMethod method = ContactMethod::kExact;
  std::vector<SegmentDescription> segments;
  /// kDynamic: mass, centre of mass, inertia and start velocity.
  RigidBodyDescription rigid;
  /// kDeformable: how. kGaussianSheet needs one segment whose mesh is the sheet's grid
  /// (make_sheet(sheet.nodes_per_side, sheet.side_m), body frame = sheet frame, z up).
  BodyDeformation deformation = BodyDeformation::kVertexDeflection;
  VirtualSheetOptions sheet;
  /// The sheet's Gaussian profile (d0, ξ, F0; the paper's by default).
  GaussianSheetParams sheet_profile;
  /// kFem: the volume, its materials, fixed nodes and solver; the body's one segment is its
  /// surface at rest (the tets' boundary, or a finer mesh embedded in them).
  std::shared_ptr<const FemBodyDescription> fem;
};

/// The most tools a world has: what a cycle's record, the run's accounting and the snapshots carry
/// per tool (a hand has five).
inline constexpr int kMaxTools = 8;

/// A contact sphere driven by the device: a stylus tip or a fingertip.
struct ToolDescription {
  std::string name;
  /// Sphere radius; 0 is a point probe.
  double radius_m = 0.005;
  /// Where the tool sits in the device's frame (rotated by the device orientation).
  Vec3 offset_device = Vec3::Zero();
  /// Device finger actuator that renders this tool's force magnitude; -1: the tool's force goes
  /// to the device tip force (summed over such tools).
  int finger = -1;
  /// Which device places the tool: 0 is the one step() is given (its command holds this tool's
  /// force); k > 0 is another user's device (World::set_device_input), whose force reaches that
  /// user through the tool's own results (a device host renders its local models), never the
  /// step's command. Index into WorldDescription::device_hosts when that is not empty.
  int device = 0;
};

struct WorldDescription {
  std::string name;
  std::vector<MaterialDescription> materials;
  std::vector<BodyDescription> bodies;
  std::vector<ToolDescription> tools;
  /// A glove drives the tools (knee paper §3.1): each tool with a finger index f sits at the
  /// virtual hand's fingertip f, from the device pose (the tracker) and joint_rad[3f..3f+2]
  /// (MCP abduction, MCP flexion, PIP; DIP coupled), instead of at a fixed device offset.
  bool has_hand = false;
  HandGeometry hand;
  /// Floor on the normal damping of every contact: b ≥ factor · k · dt. Sampling a spring at
  /// period T makes it active (Colgate & Schenkel); b > k·T/2 restores passivity, 1 gives margin.
  double passivity_damping_factor = 1.0;
  /// Gravity on dynamic bodies, world frame.
  Vec3 gravity_m_per_s2 = Vec3(0.0, 0.0, -9.81);
  /// A controller that drives some of the bodies from the device (world_controller.h: a
  /// robot's rig), or null. Shared: immutable, like the rest of the description.
  std::shared_ptr<const WorldController> controller;
  /// Several users in one world: the named device hosts (`hapsim device --name NAME`), in the
  /// order of ToolDescription::device. Empty: one device, unnamed.
  std::vector<std::string> device_hosts;
};

/// Most devices one world takes (one per user: a trainee, an instructor, two hands).
inline constexpr int kMaxWorldDevices = 4;

/// A content hash of a world description (meshes, materials, tools), as recordings carry it.
[[nodiscard]] std::string content_hash(const WorldDescription& description);

}  // namespace hapsim
