#include "hapsim/kinematics/urdf_chain.h"

#include "hapsim/core/error.h"
#include "hapsim/core/text_file.h"
#include "hapsim/geometry/csg.h"
#include "hapsim/geometry/mesh_io.h"
#include "hapsim/geometry/polygonizer.h"
#include "hapsim/geometry/procedural.h"

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

namespace hapsim {

namespace {

Iso3 to_iso(const urdf::Pose& pose) {
  double x = 0.0, y = 0.0, z = 0.0, w = 1.0;
  pose.rotation.getQuaternion(x, y, z, w);
  Iso3 X = Iso3::Identity();
  X.linear() = Quat(w, x, y, z).normalized().toRotationMatrix();
  X.translation() = Vec3(pose.position.x, pose.position.y, pose.position.z);
  return X;
}

// Line and column (1-based) of a byte offset, for messages about the raw text.
std::string text_position(std::string_view text, std::size_t byte) {
  std::size_t line = 1;
  std::size_t column = 1;
  for (std::size_t i = 0; i < byte && i < text.size(); ++i) {
    column = text[i] == '\n' ? 1 : column + 1;
    line += text[i] == '\n' ? 1 : 0;
  }
  return std::to_string(line) + ":" + std::to_string(column);
}

// Length of the UTF-8 sequence at `i` (1-4), or 0 if it is not valid UTF-8.
std::size_t utf8_length(std::string_view text, std::size_t i) {
  const auto b = static_cast<unsigned char>(text[i]);
  const std::size_t n = b < 0x80           ? 1
                        : (b >> 5) == 0x6  ? 2
                        : (b >> 4) == 0xE  ? 3
                        : (b >> 3) == 0x1E ? 4
                                           : 0;
  if (n == 0 || i + n > text.size()) {
    return 0;
  }
  for (std::size_t k = 1; k < n; ++k) {
    if ((static_cast<unsigned char>(text[i + k]) >> 6) != 0x2) {
      return 0;
    }
  }
  return n;
}

// TinyXML (under urdfdom) parses elements recursively and trusts its input to be UTF-8: a file
// nested thousands of elements deep overflows the stack, and a multi-byte lead byte at the end of
// the text makes it read past the buffer. Both are refused here, before it sees the text.
void check_xml_text(std::string_view xml, const std::string& name) {
  for (std::size_t i = 0; i < xml.size();) {
    const std::size_t n = utf8_length(xml, i);
    if (n == 0 || xml[i] == '\0') {
      throw Error(name + ":" + text_position(xml, i),
                  "not UTF-8 text (byte " + std::to_string(static_cast<unsigned char>(xml[i])) +
                      "); expected a URDF (XML)");
    }
    i += n;
  }
  constexpr int kMaxDepth = 64;  // a URDF is four levels deep (robot, link, collision, geometry)
  int depth = 0;
  for (std::size_t i = xml.find('<'); i != std::string_view::npos; i = xml.find('<', i)) {
    const std::string_view rest = xml.substr(i);
    std::string_view close = ">";
    int change = 0;
    if (rest.substr(0, 4) == "<!--") {
      close = "-->";
    } else if (rest.substr(0, 9) == "<![CDATA[") {
      close = "]]>";
    } else if (rest.substr(0, 2) == "<?") {
      close = "?>";
    } else if (rest.substr(0, 2) == "</") {
      change = -1;
    } else if (rest.substr(0, 2) != "<!") {
      change = +1;  // an opening tag, unless it closes itself
    }
    const std::size_t end = xml.find(close, i + 1);
    if (end == std::string_view::npos) {
      return;  // unterminated: TinyXML reports it
    }
    if (change == 1 && xml[end - 1] == '/') {
      change = 0;
    }
    depth = std::max(0, depth + change);
    if (depth > kMaxDepth) {
      throw Error(name + ":" + text_position(xml, i),
                  "XML nested deeper than " + std::to_string(kMaxDepth) +
                      " elements; expected a URDF (robot, link, collision, geometry)");
    }
    i = end + close.size();
  }
}

// urdfdom accepts a joint whose child is its own parent, a link that is the child of two joints
// (the last one read wins) and loops of links not reaching the root; every walk towards the root
// or down the children would then go round for ever (`hapsim fk` hung). A URDF is a tree.
void check_link_tree(const urdf::ModelInterface& model, const std::string& name) {
  std::map<std::string, std::string> parent_joint_of;  // child link -> the joint naming it
  for (const auto& [joint_name, joint] : model.joints_) {
    if (!joint) {
      continue;
    }
    if (joint->parent_link_name == joint->child_link_name) {
      throw Error(name, "joint '" + joint_name + "' names link '" + joint->child_link_name +
                            "' as both its parent and its child; expected a tree of links");
    }
    const auto [it, inserted] = parent_joint_of.emplace(joint->child_link_name, joint_name);
    if (!inserted) {
      throw Error(name, "link '" + joint->child_link_name + "' is the child of two joints ('" +
                            it->second + "' and '" + joint_name + "'); expected a tree of links");
    }
  }
  for (const auto& [link_name, link] : model.links_) {
    std::size_t steps = 0;
    for (urdf::LinkConstSharedPtr l = link; l; l = l->getParent()) {
      if (++steps > model.links_.size()) {
        const std::string joint = link->parent_joint ? link->parent_joint->name : std::string("?");
        throw Error(name, "link '" + link_name + "' is its own ancestor (through joint '" + joint +
                              "'): the joints form a cycle; expected a tree of links");
      }
    }
  }
}

int movable_joints_to_root(const urdf::ModelInterface& model, const urdf::LinkConstSharedPtr& link,
                           const std::string& base) {
  int n = 0;
  for (urdf::LinkConstSharedPtr l = link; l && l->name != base; l = l->getParent()) {
    const urdf::JointSharedPtr& j = l->parent_joint;
    if (!j) {
      return -1;  // reached the root without meeting the base: not below it
    }
    n += j->type == urdf::Joint::FIXED ? 0 : 1;
  }
  (void)model;
  return n;
}

class UrdfReader {
 public:
  UrdfReader(std::string name, std::filesystem::path folder, const UrdfChainOptions& options)
      : name_(std::move(name)), folder_(std::move(folder)), options_(options) {}

  SerialChain read(std::string_view xml) {
    // urdfdom reports parse problems through console_bridge on stderr; we report them ourselves.
    check_xml_text(xml, name_);
    const console_bridge::LogLevel level = console_bridge::getLogLevel();
    console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
    urdf::ModelInterfaceSharedPtr model;
    try {
      model = urdf::parseURDF(std::string(xml));
    } catch (const std::exception& e) {
      console_bridge::setLogLevel(level);
      throw Error(name_, std::string("not a valid URDF: ") + e.what());
    }
    console_bridge::setLogLevel(level);
    if (!model) {
      throw Error(name_,
                  "not a valid URDF (urdfdom could not read a <robot> with connected "
                  "links, named joints and known joint types from it)");
    }
    // A link urdfdom made its own child holds itself through a shared_ptr: the model would leak
    // (found by the urdf fuzz target). Its links let go of their children when we are done.
    struct ReleaseLinks {
      urdf::ModelInterface& model;
      ~ReleaseLinks() {
        for (auto& [link_name, link] : model.links_) {
          if (link) {
            link->child_links.clear();
            link->child_joints.clear();
          }
        }
      }
    } release{*model};
    check_link_tree(*model, name_);
    return build(*model);
  }

 private:
  urdf::LinkConstSharedPtr link(const urdf::ModelInterface& model, const std::string& name,
                                const char* role) const {
    urdf::LinkConstSharedPtr l = model.getLink(name);
    if (!l) {
      std::string names;
      for (const auto& [n, ptr] : model.links_) {
        names += (names.empty() ? "" : ", ") + n;
      }
      throw Error(name_, std::string("no ") + role + " link '" + name + "'; links: " + names);
    }
    return l;
  }

  SerialChain build(const urdf::ModelInterface& model) {
    const urdf::LinkConstSharedPtr root = model.getRoot();
    if (!root) {
      throw Error(name_, "the URDF has no root link");
    }
    const std::string base =
        options_.base_link.empty() ? root->name : link(model, options_.base_link, "base")->name;
    urdf::LinkConstSharedPtr tip;
    if (!options_.tip_link.empty()) {
      tip = link(model, options_.tip_link, "tip");
      if (movable_joints_to_root(model, tip, base) < 0) {
        throw Error(name_, "link '" + tip->name + "' is not below the base link '" + base + "'");
      }
    } else {
      int best = -1;
      std::vector<std::string> ties;
      for (const auto& [n, l] : model.links_) {
        if (!l->child_links.empty()) {
          continue;  // leaves only
        }
        const int depth = movable_joints_to_root(model, l, base);
        if (depth > best) {
          best = depth;
          tip = l;
          ties = {n};
        } else if (depth == best) {
          ties.push_back(n);
        }
      }
      if (ties.size() > 1) {
        std::string list;
        for (const auto& t : ties) {
          list += (list.empty() ? "" : ", ") + t;
        }
        throw Error(name_, "several tip links are equally deep (" + list + "); choose one (--tip)");
      }
      if (!tip) {
        throw Error(name_, "no link below the base link '" + base + "'");
      }
    }

    // The path base -> tip, as the links from the tip up.
    std::vector<urdf::LinkConstSharedPtr> path;
    for (urdf::LinkConstSharedPtr l = tip; l; l = l->getParent()) {
      path.push_back(l);
      if (l->name == base) {
        break;
      }
    }
    std::reverse(path.begin(), path.end());

    std::vector<ChainJoint> joints;
    Iso3 pending = Iso3::Identity();  // fixed transforms since the last movable joint's frame
    struct Attached {
      urdf::LinkConstSharedPtr link;
      int frame;
      Iso3 X_frame_link;
    };
    std::vector<Attached> attached{{path.front(), -1, Iso3::Identity()}};
    for (std::size_t k = 1; k < path.size(); ++k) {
      const urdf::JointSharedPtr& uj = path[k]->parent_joint;
      const Iso3 origin = to_iso(uj->parent_to_joint_origin_transform);
      const std::string where = name_ + ": joint '" + uj->name + "'";
      switch (uj->type) {
        case urdf::Joint::FIXED:
          pending = pending * origin;
          break;
        case urdf::Joint::REVOLUTE:
        case urdf::Joint::CONTINUOUS:
        case urdf::Joint::PRISMATIC: {
          ChainJoint j;
          j.name = uj->name;
          j.type =
              uj->type == urdf::Joint::PRISMATIC ? JointType::kPrismatic : JointType::kRevolute;
          j.X_parent_joint = pending * origin;
          j.axis = Vec3(uj->axis.x, uj->axis.y, uj->axis.z);
          if (uj->type != urdf::Joint::CONTINUOUS && uj->limits) {
            j.lower = uj->limits->lower;
            j.upper = uj->limits->upper;
          }
          if (uj->limits && uj->limits->velocity > 0.0) {
            j.max_velocity = uj->limits->velocity;
          }
          j.child_link = path[k]->name;
          try {
            (void)SerialChain("", {j}, Iso3::Identity(), "");  // checks this joint alone
          } catch (const Error& e) {
            throw Error(where, e.detail());
          }
          joints.push_back(std::move(j));
          pending = Iso3::Identity();
          break;
        }
        default:
          throw Error(where,
                      "is floating or planar; a serial chain takes revolute, continuous, "
                      "prismatic and fixed joints");
      }
      attached.push_back({path[k], static_cast<int>(joints.size()) - 1, pending});
    }
    SerialChain chain(base, std::move(joints), pending, tip->name);
    if (options_.load_collision_meshes) {
      std::vector<ChainLinkGeometry> links;
      for (const Attached& a : attached) {
        add_collision(*a.link, a.frame, a.X_frame_link, links);
      }
      chain.set_link_geometry(std::move(links));
    }
    std::vector<ChainLinkVisual> visuals;
    for (const Attached& a : attached) {
      add_visuals(*a.link, a.frame, a.X_frame_link, visuals);
    }
    chain.set_link_visuals(std::move(visuals));
    return chain;
  }

  void add_collision(const urdf::Link& link, int frame, const Iso3& X_frame_link,
                     std::vector<ChainLinkGeometry>& out) const {
    std::size_t index = 0;
    for (const urdf::CollisionSharedPtr& c : link.collision_array) {
      if (!c || !c->geometry) {
        continue;
      }
      const std::string where =
          name_ + ": link '" + link.name + "' collision " + std::to_string(index++);
      ChainLinkGeometry g;
      g.link = link.name;
      g.frame = frame;
      g.X_frame_mesh = X_frame_link * to_iso(c->origin);
      g.mesh = geometry_mesh(*c->geometry, where);
      out.push_back(std::move(g));
    }
  }

  // A link's visuals: mesh files by path (loaded by the display), primitives tessellated here.
  // Nothing here fails the chain: a visual that cannot be drawn is left out and the link is drawn
  // from its collision shape.
  void add_visuals(const urdf::Link& link, int frame, const Iso3& X_frame_link,
                   std::vector<ChainLinkVisual>& out) const {
    std::size_t index = 0;
    for (const urdf::VisualSharedPtr& v : link.visual_array) {
      if (!v || !v->geometry) {
        continue;
      }
      const std::string where =
          name_ + ": link '" + link.name + "' visual " + std::to_string(index++);
      ChainLinkVisual visual;
      visual.link = link.name;
      visual.frame = frame;
      visual.X_frame_mesh = X_frame_link * to_iso(v->origin);
      if (v->material) {
        const urdf::Color& c = v->material->color;
        visual.has_colour = std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b);
        visual.colour = Vec3f(std::clamp(c.r, 0.0f, 1.0f), std::clamp(c.g, 0.0f, 1.0f),
                              std::clamp(c.b, 0.0f, 1.0f));
      }
      if (v->geometry->type == urdf::Geometry::MESH) {
        const auto& m = static_cast<const urdf::Mesh&>(*v->geometry);
        std::string file = m.filename;
        if (file.rfind("file://", 0) == 0) {
          file = file.substr(7);
        }
        std::filesystem::path p(file);
        if (file.rfind("package://", 0) == 0 ||
            !(m.scale.x > 0.0 && m.scale.y > 0.0 && m.scale.z > 0.0)) {
          continue;  // needs ROS, or degenerate: the collision shape stands in
        }
        visual.mesh_file = (p.is_relative() ? folder_ / p : p).string();
        visual.mesh_scale = Vec3(m.scale.x, m.scale.y, m.scale.z);
      } else {
        try {
          visual.mesh = geometry_mesh(*v->geometry, where);
        } catch (const Error&) {
          continue;
        }
      }
      out.push_back(std::move(visual));
    }
  }

  TriangleMesh geometry_mesh(const urdf::Geometry& geometry, const std::string& where) const {
    switch (geometry.type) {
      case urdf::Geometry::MESH: {
        const auto& m = static_cast<const urdf::Mesh&>(geometry);
        std::string file = m.filename;
        if (file.rfind("package://", 0) == 0) {
          throw Error(where, "mesh '" + file +
                                 "': package:// paths need ROS; give a path relative to the URDF");
        }
        if (file.rfind("file://", 0) == 0) {
          file = file.substr(7);
        }
        std::filesystem::path p(file);
        if (p.is_relative()) {
          p = folder_ / p;
        }
        TriangleMesh mesh;
        try {
          mesh = load_mesh(p);
        } catch (const Error& e) {
          throw Error(where, "cannot load mesh " + e.where() + ": " + e.detail());
        }
        const Vec3 scale(m.scale.x, m.scale.y, m.scale.z);
        if (!(scale.minCoeff() > 0.0) || !scale.allFinite()) {
          throw Error(where, "mesh scale must be > 0 on every axis");
        }
        if (scale != Vec3::Ones()) {
          for (Vec3& v : mesh.vertices) {
            v = v.cwiseProduct(scale);
          }
          mesh.compute_vertex_normals();
        }
        return mesh;
      }
      case urdf::Geometry::BOX: {
        const auto& b = static_cast<const urdf::Box&>(geometry);
        const Vec3 half(b.dim.x / 2, b.dim.y / 2, b.dim.z / 2);
        if (!(half.minCoeff() > 0.0)) {
          throw Error(where, "box size must be > 0 on every axis");
        }
        return make_box(half);
      }
      case urdf::Geometry::SPHERE: {
        const auto& s = static_cast<const urdf::Sphere&>(geometry);
        if (!(s.radius > 0.0)) {
          throw Error(where, "sphere radius must be > 0");
        }
        return make_uv_sphere(s.radius, 32, 16);
      }
      case urdf::Geometry::CYLINDER: {
        const auto& c = static_cast<const urdf::Cylinder&>(geometry);
        if (!(c.radius > 0.0) || !(c.length > 0.0)) {
          throw Error(where, "cylinder radius and length must be > 0");
        }
        PolygonizeOptions po;
        po.max_cells_per_axis = 40;
        po.threads = 1;
        TriangleMesh mesh = polygonize(CsgSolid::cylinder(c.radius, c.length / 2), po);
        mesh.compute_vertex_normals();
        return mesh;
      }
    }
    throw Error(where, "unknown collision geometry type");
  }

  std::string name_;
  std::filesystem::path folder_;
  UrdfChainOptions options_;
};

}  // namespace

SerialChain parse_urdf_chain(std::string_view urdf_xml, std::string_view name,
                             const std::filesystem::path& folder, const UrdfChainOptions& options) {
  return UrdfReader(std::string(name), folder, options).read(urdf_xml);
}

SerialChain load_urdf_chain(const std::filesystem::path& file, const UrdfChainOptions& options) {
  constexpr std::size_t kMaxUrdfBytes = std::size_t{16} << 20;  // the GP7's is 9 kB
  return parse_urdf_chain(read_text_file(file, kMaxUrdfBytes, "URDF file"), file.string(),
                          file.parent_path(), options);
}

}  // namespace hapsim
