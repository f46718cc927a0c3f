#include "hapsim/render/world_scene.h"

#include "hapsim/collision/knee_groups.h"
#include "hapsim/collision/sphere_tree.h"
#include "hapsim/core/error.h"

#include <algorithm>
#include <cctype>
#include <string>

namespace hapsim {

struct WorldScene::Segment {
  std::size_t body = 0;
  std::size_t index_in_body = 0;
  MeshId mesh = 0;
  std::string label;
  Vec3f tissue_colour = Vec3f::Ones();
  bool deformable = false;
  std::uint64_t version = 0;
  std::unique_ptr<SphereTree> tree;  // built when a sphere-tree level is first shown
  std::vector<Vec3f> group_colours;  // built when group colouring is first asked for
};

namespace {

bool contains(const std::string& haystack, std::string_view needle) {
  return haystack.find(needle) != std::string::npos;
}

}  // namespace

Vec3f WorldScene::tissue_colour(std::string_view material_name, int material_index) {
  std::string n(material_name);
  std::transform(n.begin(), n.end(), n.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (contains(n, "cartilage") || contains(n, "meniscus")) {
    return {0.70f, 0.82f, 0.90f};
  }
  if (contains(n, "bone") || contains(n, "cortical")) {
    return {0.93f, 0.89f, 0.78f};
  }
  if (contains(n, "ligament") || contains(n, "tendon")) {
    return {0.95f, 0.90f, 0.60f};
  }
  if (contains(n, "muscle")) {
    return {0.72f, 0.25f, 0.22f};
  }
  if (contains(n, "skin") || contains(n, "fat")) {
    return {0.94f, 0.76f, 0.64f};
  }
  if (contains(n, "sheet")) {
    return {0.55f, 0.75f, 0.95f};
  }
  if (contains(n, "table") || contains(n, "wood")) {
    return {0.62f, 0.46f, 0.30f};
  }
  if (contains(n, "ball") || contains(n, "rubber")) {
    return {0.95f, 0.55f, 0.15f};
  }
  return palette_colour(material_index);
}

WorldScene::WorldScene(const World& world, WorldSceneOptions options)
    : world_(world), options_(options) {
  const WorldDescription& d = world.description();
  segments_.resize(world.flat_segment_count());
  for (std::size_t b = 0; b < d.bodies.size(); ++b) {
    const BodyDescription& body = d.bodies[b];
    for (std::size_t s = 0; s < body.segments.size(); ++s) {
      const SegmentDescription& sd = body.segments[s];
      auto seg = std::make_unique<Segment>();
      seg->body = b;
      seg->index_in_body = s;
      seg->label = body.name + "/" + sd.name;
      seg->deformable = body.kind == BodyKind::kDeformable;
      const MaterialDescription& m = d.materials.at(sd.material);
      seg->tissue_colour = tissue_colour(m.name, static_cast<int>(sd.material));
      seg->mesh = scene_.add_mesh(sd.mesh, seg->tissue_colour, body.X_world_body);
      scene_.mesh(seg->mesh).name = seg->label;
      for (const Vec3& v : sd.mesh.vertices) {
        rest_bounds_world_.extend(body.X_world_body * v);
      }
      segments_[world.flat_segment(b, s)] = std::move(seg);
    }
    body_poses_.push_back(body.X_world_body);
  }
  // A floor just under the bodies, a little wider than them, with 1 cm checks for scale.
  if (!rest_bounds_world_.isEmpty()) {
    const Vec3 c = rest_bounds_world_.center();
    const double half = 0.75 * rest_bounds_world_.sizes().head<2>().maxCoeff() + 0.05;
    scene_.floor.height_m = rest_bounds_world_.min().z() - 0.002;
    scene_.floor.centre_x_m = c.x();
    scene_.floor.centre_y_m = c.y();
    scene_.floor.half_extent_m = half;
    scene_.floor.cell_m = half > 0.3 ? 0.05 : 0.01;
  }
  tools_.resize(d.tools.size());
  tool_force_n_.assign(d.tools.size(), 0.0);
  apply_colouring();
}

WorldScene::~WorldScene() = default;

void WorldScene::set_options(const WorldSceneOptions& options) {
  const bool recolour = options.colouring != options_.colouring;
  options_ = options;
  if (recolour) {
    apply_colouring();
  }
  rebuild_overlays(tools_, tool_force_n_);
}

void WorldScene::set_segment_visible(std::size_t flat_segment, bool visible) {
  scene_.mesh(segments_.at(flat_segment)->mesh).visible = visible;
}

bool WorldScene::segment_visible(std::size_t flat_segment) const {
  return scene_.mesh(segments_.at(flat_segment)->mesh).visible;
}

const std::string& WorldScene::segment_label(std::size_t flat_segment) const {
  return segments_.at(flat_segment)->label;
}

void WorldScene::apply_colouring() {
  const WorldDescription& d = world_.description();
  int next_group_colour = 0;
  for (std::size_t i = 0; i < segments_.size(); ++i) {
    Segment& seg = *segments_[i];
    RenderMesh& mesh = scene_.mesh(seg.mesh);
    switch (options_.colouring) {
      case SegmentColouring::kTissue:
        mesh.colour = seg.tissue_colour;
        scene_.set_vertex_colours(seg.mesh, {});
        break;
      case SegmentColouring::kSegments:
        mesh.colour = palette_colour(static_cast<int>(i));
        scene_.set_vertex_colours(seg.mesh, {});
        break;
      case SegmentColouring::kGroups: {
        if (seg.group_colours.empty()) {
          const TriangleMesh& rest = d.bodies[seg.body].segments[seg.index_in_body].mesh;
          const KneeGrouping grouping = build_knee_groups(rest);
          seg.group_colours.resize(rest.vertices.size(), seg.tissue_colour);
          for (std::size_t v = 0; v < grouping.vertex_group.size(); ++v) {
            seg.group_colours[v] =
                palette_colour(next_group_colour + static_cast<int>(grouping.vertex_group[v]));
          }
          next_group_colour += static_cast<int>(grouping.groups.size());
        }
        scene_.set_vertex_colours(seg.mesh, seg.group_colours);
        break;
      }
    }
  }
}

void WorldScene::update(const WorldSnapshot& snapshot) {
  if (snapshot.body_poses_world.size() == body_poses_.size()) {
    body_poses_ = snapshot.body_poses_world;
  }
  for (std::size_t i = 0; i < segments_.size(); ++i) {
    Segment& seg = *segments_[i];
    scene_.mesh(seg.mesh).X_world_mesh = body_poses_[seg.body];
    if (!seg.deformable || i >= snapshot.positions_body.size() ||
        snapshot.positions_version[i] == seg.version) {
      continue;
    }
    const std::vector<float>& xyz = snapshot.positions_body[i];
    scratch_positions_.resize(xyz.size() / 3);
    for (std::size_t v = 0; v < scratch_positions_.size(); ++v) {
      scratch_positions_[v] = Vec3(xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]);
    }
    scene_.update_positions(seg.mesh, scratch_positions_);
    seg.version = snapshot.positions_version[i];
  }
  rebuild_overlays(snapshot.tools, snapshot.tool_force_n);
}

void WorldScene::update_from_world(const World& world) {
  for (std::size_t b = 0; b < body_poses_.size(); ++b) {
    body_poses_[b] = world.body_pose(b);
  }
  for (const auto& seg : segments_) {
    scene_.mesh(seg->mesh).X_world_mesh = body_poses_[seg->body];
    if (seg->deformable) {
      scene_.update_positions(seg->mesh, world.surface(seg->body, seg->index_in_body).vertices);
    }
  }
  const StepResult& r = world.last_result();
  std::vector<double> force_n(r.tools.size());
  for (std::size_t t = 0; t < r.tools.size(); ++t) {
    force_n[t] = r.tools[t].force_world_n.norm();
  }
  rebuild_overlays({r.tools.begin(), r.tools.end()}, force_n);
}

void WorldScene::rebuild_overlays(const std::vector<ToolState>& tools,
                                  const std::vector<double>& force_n) {
  if (&tools != &tools_) {
    tools_ = tools;
  }
  if (&force_n != &tool_force_n_) {
    tool_force_n_ = force_n;
  }
  const WorldDescription& d = world_.description();
  scene_.spheres.clear();
  scene_.segments.clear();
  scene_.shadow_marks.clear();
  const double scale =
      std::max(0.05, rest_bounds_world_.isEmpty() ? 0.1 : rest_bounds_world_.sizes().norm());
  for (std::size_t t = 0; t < tools_.size() && t < d.tools.size(); ++t) {
    const ToolState& tool = tools_[t];
    const double f = t < tool_force_n_.size() ? tool_force_n_[t] : 0.0;
    // Green when free, towards red as the force grows (10 N full red).
    const float heat = static_cast<float>(std::clamp(f / 10.0, 0.0, 1.0));
    const double radius = std::max(d.tools[t].radius_m, 0.002);
    scene_.spheres.push_back(
        {tool.p_world, radius, Vec3f(0.2f + 0.75f * heat, 0.8f - 0.6f * heat, 0.25f), false});
    if (options_.show_proxies && (tool.proxy_world - tool.p_world).norm() > 1e-4) {
      scene_.spheres.push_back({tool.proxy_world, radius, Vec3f(0.3f, 0.6f, 1.0f), true});
      scene_.segments.push_back({tool.p_world, tool.proxy_world, Vec3f(0.3f, 0.6f, 1.0f)});
    }
    if (options_.show_force_arrows && tool.force_world_n.norm() > 1e-6) {
      scene_.segments.push_back({tool.p_world,
                                 tool.p_world + options_.arrow_m_per_n * tool.force_world_n,
                                 Vec3f(1.0f, 0.9f, 0.1f)});
    }
    scene_.shadow_marks.push_back(
        {tool.p_world, 0.04 * scale, 0.006 * scale, Vec3f(0.1f, 0.1f, 0.12f)});
  }
  if (options_.sphere_tree_level >= 0) {
    for (auto& seg : segments_) {
      if (!scene_.mesh(seg->mesh).visible) {
        continue;
      }
      if (!seg->tree) {
        seg->tree =
            std::make_unique<SphereTree>(d.bodies[seg->body].segments[seg->index_in_body].mesh);
      }
      const Iso3& X = body_poses_[seg->body];
      const auto level = static_cast<std::size_t>(options_.sphere_tree_level);
      for (std::size_t n = 0; n < seg->tree->node_count(); ++n) {
        const std::size_t node_level = seg->tree->node_level(n);
        // A leaf above the chosen level stands in for its missing descendants.
        if (node_level == level || (node_level < level && seg->tree->node_children(n).empty())) {
          const Sphere s = seg->tree->node_sphere(n);
          scene_.spheres.push_back(
              {X * s.center, s.radius, palette_colour(static_cast<int>(n % 10)), true});
        }
      }
    }
  }
}

}  // namespace hapsim
