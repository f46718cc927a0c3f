#include "hapsim/render/renderer.h"

#include "hapsim/core/error.h"
#include "hapsim/geometry/mesh_lod.h"
#include "hapsim/geometry/procedural.h"
#include "hapsim/render/gl_api.h"
#include "hapsim/render/lod_selection.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <span>
#include <vector>

namespace hapsim {
namespace {

constexpr const char* kWhere = "Renderer";

// Lit geometry: Gouraud shading, i.e. the lighting equation runs here, per vertex; for both faces
// where TWO_SIDED is 1 (gl_FrontFacing picks one in the fragment shader). Camera frame (C): x
// right, y up, z back. Compiled twice (Impl::lit_two_sided, Impl::lit_one_sided): a uniform choice
// would not save the second shading on llvmpipe, which evaluates both sides of a select.
constexpr const char* kLitVertexBody = R"(
layout(location = 0) in vec3 a_position_M;
layout(location = 1) in vec3 a_normal_M;
layout(location = 2) in vec3 a_colour;
uniform mat4 u_model_view;
uniform mat4 u_projection;
uniform vec3 u_colour;
uniform bool u_use_vertex_colour;
uniform int u_light_count;
uniform vec3 u_light_dir_camera[4];
uniform vec3 u_light_colour[4];
uniform vec3 u_ambient;
uniform float u_specular;
uniform float u_shininess;
uniform float u_point_size;
out vec3 v_front_colour;
out vec3 v_back_colour;

vec3 shade(vec3 n_camera, vec3 to_eye_camera, vec3 base) {
  vec3 c = u_ambient * base;
  for (int i = 0; i < u_light_count; ++i) {
    vec3 l = u_light_dir_camera[i];
    float lambert = max(dot(n_camera, l), 0.0);
    float spec = 0.0;
    if (lambert > 0.0) {
      spec = pow(max(dot(n_camera, normalize(l + to_eye_camera)), 0.0), u_shininess);
    }
    c += u_light_colour[i] * (lambert * base + u_specular * spec);
  }
  return c;
}

void main() {
  vec4 p_camera = u_model_view * vec4(a_position_M, 1.0);
  vec3 to_eye_camera = normalize(-p_camera.xyz);
  vec3 n = mat3(u_model_view) * a_normal_M;  // rigid pose (+ uniform scale for spheres)
  vec3 n_camera = dot(n, n) > 0.0 ? normalize(n) : to_eye_camera;
  vec3 base = u_use_vertex_colour ? a_colour : u_colour;
  v_front_colour = shade(n_camera, to_eye_camera, base);
#if TWO_SIDED
  v_back_colour = shade(-n_camera, to_eye_camera, base);
#else
  v_back_colour = v_front_colour;  // a closed mesh's back faces are culled: no back to light
#endif
  gl_Position = u_projection * p_camera;
  gl_PointSize = u_point_size;
}
)";

constexpr const char* kLitFragment = R"(#version 330 core
in vec3 v_front_colour;
in vec3 v_back_colour;
uniform float u_opacity;
out vec4 o_colour;
void main() {
  o_colour = vec4(gl_FrontFacing ? v_front_colour : v_back_colour, u_opacity);
}
)";

// Unlit, per-vertex coloured lines and triangles given in the world frame (segments, marks).
constexpr const char* kUnlitVertex = R"(#version 330 core
layout(location = 0) in vec3 a_position_world;
layout(location = 1) in vec3 a_colour;
uniform mat4 u_view_projection;
out vec3 v_colour;
void main() {
  gl_Position = u_view_projection * vec4(a_position_world, 1.0);
  v_colour = a_colour;
}
)";

constexpr const char* kUnlitFragment = R"(#version 330 core
in vec3 v_colour;
out vec4 o_colour;
void main() { o_colour = vec4(v_colour, 1.0); }
)";

// Floor: a checkerboard computed from the world position, so it needs no texture.
constexpr const char* kFloorVertex = R"(#version 330 core
layout(location = 0) in vec3 a_position_world;
uniform mat4 u_view_projection;
out vec2 v_xy_world;
void main() {
  gl_Position = u_view_projection * vec4(a_position_world, 1.0);
  v_xy_world = a_position_world.xy;
}
)";

constexpr const char* kFloorFragment = R"(#version 330 core
in vec2 v_xy_world;
uniform float u_cell_m;
uniform vec2 u_origin_xy_world;
uniform vec3 u_colour_a;
uniform vec3 u_colour_b;
out vec4 o_colour;
void main() {
  ivec2 cell = ivec2(floor((v_xy_world - u_origin_xy_world) / u_cell_m));
  o_colour = vec4(((cell.x + cell.y) & 1) == 0 ? u_colour_a : u_colour_b, 1.0);
}
)";

GLuint compile_shader(GLenum type, const char* source, const char* name) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    std::array<char, 2048> log{};
    glGetShaderInfoLog(shader, static_cast<GLsizei>(log.size()), nullptr, log.data());
    glDeleteShader(shader);
    throw Error(kWhere, std::string("GL: shader '") + name + "' failed to compile: " + log.data());
  }
  return shader;
}

GLuint link_program(const char* vertex, const char* fragment, const char* name) {
  const GLuint vs = compile_shader(GL_VERTEX_SHADER, vertex, name);
  const GLuint fs = compile_shader(GL_FRAGMENT_SHADER, fragment, name);
  const GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);  // flagged; freed with the program
  glDeleteShader(fs);
  GLint ok = GL_FALSE;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    std::array<char, 2048> log{};
    glGetProgramInfoLog(program, static_cast<GLsizei>(log.size()), nullptr, log.data());
    glDeleteProgram(program);
    throw Error(kWhere, std::string("GL: program '") + name + "' failed to link: " + log.data());
  }
  return program;
}

void set_matrix(GLint location, const Eigen::Matrix4f& m) {
  glUniformMatrix4fv(location, 1, GL_FALSE, m.data());  // Eigen is column-major, as GL expects
}

void set_vec3(GLint location, const Vec3f& v) {
  glUniform3f(location, v.x(), v.y(), v.z());
}

// Interleaved vertex layout of lit meshes: position, normal, colour (9 floats).
constexpr int kLitFloats = 9;
// Interleaved vertex layout of the stream buffer: world position, colour (6 floats).
constexpr int kUnlitFloats = 6;

const void* byte_offset(std::size_t floats) {
  // GL's buffer-offset idiom: the "pointer" is a byte offset into the bound buffer.
  // NOLINTNEXTLINE(performance-no-int-to-ptr)
  return reinterpret_cast<const void*>(floats * sizeof(float));
}

static_assert(sizeof(TriangleIndices) == 3 * sizeof(std::uint32_t), "indices upload as is");

// An open tube of radius 1 from z = 0 to z = 1 with radial normals: a capsule's body, scaled by
// (r, r, length) per instance (the normals stay radial under that scale, so the shader's
// normalize() makes them right).
TriangleMesh make_unit_tube(int segments) {
  TriangleMesh m;
  for (int i = 0; i < segments; ++i) {
    const double a = 2.0 * std::numbers::pi * i / segments;
    const Vec3 radial(std::cos(a), std::sin(a), 0.0);
    m.vertices.push_back(radial);
    m.vertices.push_back(radial + Vec3::UnitZ());
    m.vertex_normals.push_back(radial);
    m.vertex_normals.push_back(radial);
  }
  for (int i = 0; i < segments; ++i) {
    const auto a0 = static_cast<std::uint32_t>(2 * i);
    const auto a1 = static_cast<std::uint32_t>(2 * ((i + 1) % segments));
    m.triangles.push_back({a0, a1, a0 + 1});
    m.triangles.push_back({a1, a1 + 1, a0 + 1});
  }
  return m;
}

// GPU copy of one mesh.
struct GpuMesh {
  GLuint vao = 0;
  GLuint vbo = 0;
  GLuint ibo = 0;
  GLsizei vertex_count = 0;
  GLsizei index_count = 0;
  // Levels of detail: level 0 (the full mesh) then the coarser ones, back to back in the one
  // index buffer (first index and count each), their errors, the level drawn last.
  std::vector<GLsizei> level_first;
  std::vector<GLsizei> level_count;
  std::vector<double> level_error_m;
  std::size_t level = 0;
  bool has_vertex_colours = false;
  std::uint64_t topology_stamp = 0;
  std::uint64_t vertex_stamp = 0;

  void create() {
    glGenVertexArrays(1, &vao);
    glGenBuffers(1, &vbo);
    glGenBuffers(1, &ibo);
    glBindVertexArray(vao);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo);  // recorded in the VAO
    const auto stride = static_cast<GLsizei>(kLitFloats * sizeof(float));
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, byte_offset(0));
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride, byte_offset(3));
    glVertexAttribPointer(2, 3, GL_FLOAT, GL_FALSE, stride, byte_offset(6));
    glEnableVertexAttribArray(0);
    glEnableVertexAttribArray(1);
    glEnableVertexAttribArray(2);
    glBindVertexArray(0);
  }

  void destroy() {
    glDeleteBuffers(1, &vbo);
    glDeleteBuffers(1, &ibo);
    glDeleteVertexArrays(1, &vao);
    vao = vbo = ibo = 0;
  }
};

struct LitUniforms {
  GLint model_view = -1, projection = -1, colour = -1, use_vertex_colour = -1, light_count = -1,
        light_dir = -1, light_colour = -1, ambient = -1, specular = -1, shininess = -1,
        point_size = -1, opacity = -1;
};

// One of the lit program's two variants with its uniforms' locations.
struct LitProgram {
  GLuint id = 0;
  LitUniforms u;
};

}  // namespace

struct Renderer::Impl {
  // Both faces lit (open sheets and cut meshes, points, lines, spheres), and front faces only
  // (closed meshes drawn as faces, back faces culled: half the vertex shading).
  LitProgram lit_two_sided;
  LitProgram lit_one_sided;
  GLuint unlit = 0;
  GLuint floor = 0;
  GLint unlit_view_projection = -1;
  GLint floor_view_projection = -1, floor_cell = -1, floor_origin = -1, floor_colour_a = -1,
        floor_colour_b = -1;
  float max_line_width = 1.0f;

  std::vector<GpuMesh> meshes;  // by MeshId
  GpuMesh sphere;               // unit sphere, scaled per instance
  GpuMesh tube;                 // unit open tube: capsules' bodies
  GLuint stream_vao = 0;
  GLuint stream_vbo = 0;
  std::size_t stream_capacity_bytes = 0;
  std::vector<float> staging;  // reused for uploads and the per-frame stream
  RenderStats stats;

  void upload(GpuMesh& gpu, const TriangleMesh& geometry, const std::vector<Vec3f>& colours,
              bool topology_changed, std::span<const LodLevel> levels = {}) {
    const std::size_t n = geometry.vertices.size();
    staging.resize(n * kLitFloats);
    for (std::size_t i = 0; i < n; ++i) {
      float* v = &staging[i * kLitFloats];
      const Vec3& p = geometry.vertices[i];
      const Vec3 nrm =
          i < geometry.vertex_normals.size() ? geometry.vertex_normals[i] : Vec3::Zero();
      const Vec3f c = i < colours.size() ? colours[i] : Vec3f::Ones();
      v[0] = static_cast<float>(p.x());
      v[1] = static_cast<float>(p.y());
      v[2] = static_cast<float>(p.z());
      v[3] = static_cast<float>(nrm.x());
      v[4] = static_cast<float>(nrm.y());
      v[5] = static_cast<float>(nrm.z());
      v[6] = c.x();
      v[7] = c.y();
      v[8] = c.z();
    }
    const auto bytes = static_cast<GLsizeiptr>(staging.size() * sizeof(float));
    glBindBuffer(GL_ARRAY_BUFFER, gpu.vbo);
    if (topology_changed || gpu.vertex_count != static_cast<GLsizei>(n)) {
      glBufferData(GL_ARRAY_BUFFER, bytes, staging.data(), GL_DYNAMIC_DRAW);
    } else {
      glBufferSubData(GL_ARRAY_BUFFER, 0, bytes, staging.data());
    }
    if (topology_changed) {
      gpu.level_first.assign(1, 0);
      gpu.level_count.assign(1, static_cast<GLsizei>(geometry.triangles.size() * 3));
      gpu.level_error_m.assign(1, 0.0);
      gpu.level = 0;
      std::size_t triangles = geometry.triangles.size();
      for (const LodLevel& l : levels) {
        gpu.level_first.push_back(static_cast<GLsizei>(3 * triangles));
        gpu.level_count.push_back(static_cast<GLsizei>(3 * l.triangles.size()));
        gpu.level_error_m.push_back(l.error_m);
        triangles += l.triangles.size();
      }
      glBindVertexArray(gpu.vao);  // the element buffer binding is VAO state
      glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, gpu.ibo);
      glBufferData(GL_ELEMENT_ARRAY_BUFFER,
                   static_cast<GLsizeiptr>(triangles * sizeof(TriangleIndices)), nullptr,
                   GL_STATIC_DRAW);
      // The full mesh reordered for vertex reuse (its coarser levels already are): llvmpipe shades
      // a vertex again in every batch it appears in. Once per topology, not per frame.
      const std::vector<TriangleIndices> full = vertex_cache_order(geometry.triangles, n);
      glBufferSubData(GL_ELEMENT_ARRAY_BUFFER, 0,
                      static_cast<GLsizeiptr>(full.size() * sizeof(TriangleIndices)), full.data());
      for (std::size_t i = 0; i < levels.size(); ++i) {
        glBufferSubData(
            GL_ELEMENT_ARRAY_BUFFER,
            static_cast<GLintptr>(gpu.level_first[i + 1]) *
                static_cast<GLintptr>(sizeof(std::uint32_t)),
            static_cast<GLsizeiptr>(levels[i].triangles.size() * sizeof(TriangleIndices)),
            levels[i].triangles.data());
      }
      gpu.index_count = gpu.level_count[0];
    }
    glBindVertexArray(0);
    gpu.vertex_count = static_cast<GLsizei>(n);
    gpu.has_vertex_colours = colours.size() == n && n > 0;
  }

  void sync_meshes(const RenderScene& scene) {
    if (meshes.size() < scene.mesh_count()) {
      meshes.resize(scene.mesh_count());
    }
    for (MeshId id = 0; id < scene.mesh_count(); ++id) {
      const RenderMesh& m = scene.mesh(id);
      GpuMesh& gpu = meshes[id];
      if (gpu.vao == 0) {
        gpu.create();
      }
      const bool topology_changed = gpu.topology_stamp != m.topology_stamp();
      if (topology_changed || gpu.vertex_stamp != m.vertex_stamp()) {
        upload(gpu, m.geometry(), m.vertex_colours(), topology_changed, m.lod_levels());
        gpu.topology_stamp = m.topology_stamp();
        gpu.vertex_stamp = m.vertex_stamp();
      }
    }
  }

  // Appends one unlit vertex to the stream.
  void push(const Vec3& p_world, const Vec3f& c) {
    staging.insert(staging.end(), {static_cast<float>(p_world.x()), static_cast<float>(p_world.y()),
                                   static_cast<float>(p_world.z()), c.x(), c.y(), c.z()});
  }

  static void set_lit_lighting(const LitUniforms& lit_u, const Lighting& lighting,
                               const Eigen::Matrix3d& R_CW) {
    constexpr auto kSlots = 3 * static_cast<std::size_t>(Lighting::kMaxLights);
    std::array<float, kSlots> dirs{};
    std::array<float, kSlots> colours{};
    const int count = std::min(static_cast<int>(lighting.lights.size()), Lighting::kMaxLights);
    for (int i = 0; i < count; ++i) {
      const DirectionalLight& light = lighting.lights[static_cast<std::size_t>(i)];
      Vec3 d_camera = light.frame == LightFrame::kWorld ? Vec3(R_CW * light.direction_to_light)
                                                        : light.direction_to_light;
      d_camera.normalize();
      const auto base = 3 * static_cast<std::size_t>(i);
      for (int k = 0; k < 3; ++k) {
        dirs[base + static_cast<std::size_t>(k)] = static_cast<float>(d_camera[k]);
        colours[base + static_cast<std::size_t>(k)] = light.colour[k];
      }
    }
    glUniform1i(lit_u.light_count, count);
    glUniform3fv(lit_u.light_dir, Lighting::kMaxLights, dirs.data());
    glUniform3fv(lit_u.light_colour, Lighting::kMaxLights, colours.data());
    set_vec3(lit_u.ambient, lighting.ambient);
    glUniform1f(lit_u.specular, lighting.specular);
    glUniform1f(lit_u.shininess, lighting.shininess);
  }
};

Renderer::Renderer() : impl_(std::make_unique<Impl>()) {
  const auto* version = glGetString(GL_VERSION);
  if (version == nullptr) {
    throw Error(kWhere, "no current OpenGL context (create an OffscreenContext or a window first)");
  }
  GLint major = 0;
  GLint minor = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &major);
  glGetIntegerv(GL_MINOR_VERSION, &minor);
  if (major * 10 + minor < 33) {
    throw Error(kWhere, std::string("OpenGL 3.3 core needed, the context has ") +
                            reinterpret_cast<const char*>(version));
  }
  Impl& s = *impl_;
  const auto loc = [](GLuint program, const char* name) {
    return glGetUniformLocation(program, name);
  };
  const auto make_lit = [&](bool two_sided) {
    const std::string vertex = std::string("#version 330 core\n#define TWO_SIDED ") +
                               (two_sided ? "1" : "0") + kLitVertexBody;
    LitProgram p;
    p.id = link_program(vertex.c_str(), kLitFragment, two_sided ? "lit" : "lit (one-sided)");
    p.u.model_view = loc(p.id, "u_model_view");
    p.u.projection = loc(p.id, "u_projection");
    p.u.colour = loc(p.id, "u_colour");
    p.u.opacity = loc(p.id, "u_opacity");
    p.u.use_vertex_colour = loc(p.id, "u_use_vertex_colour");
    p.u.light_count = loc(p.id, "u_light_count");
    p.u.light_dir = loc(p.id, "u_light_dir_camera");
    p.u.light_colour = loc(p.id, "u_light_colour");
    p.u.ambient = loc(p.id, "u_ambient");
    p.u.specular = loc(p.id, "u_specular");
    p.u.shininess = loc(p.id, "u_shininess");
    p.u.point_size = loc(p.id, "u_point_size");
    return p;
  };
  s.lit_two_sided = make_lit(true);
  s.lit_one_sided = make_lit(false);
  s.unlit = link_program(kUnlitVertex, kUnlitFragment, "unlit");
  s.floor = link_program(kFloorVertex, kFloorFragment, "floor");
  s.unlit_view_projection = loc(s.unlit, "u_view_projection");
  s.floor_view_projection = loc(s.floor, "u_view_projection");
  s.floor_cell = loc(s.floor, "u_cell_m");
  s.floor_origin = loc(s.floor, "u_origin_xy_world");
  s.floor_colour_a = loc(s.floor, "u_colour_a");
  s.floor_colour_b = loc(s.floor, "u_colour_b");

  // Wide lines are deprecated in core and rejected by forward-compatible contexts.
  GLint flags = 0;
  glGetIntegerv(GL_CONTEXT_FLAGS, &flags);
  if ((flags & GL_CONTEXT_FLAG_FORWARD_COMPATIBLE_BIT) == 0) {
    std::array<GLfloat, 2> range{1.0f, 1.0f};
    glGetFloatv(GL_ALIASED_LINE_WIDTH_RANGE, range.data());
    s.max_line_width = std::max(1.0f, range[1]);
  }

  s.sphere.create();
  s.upload(s.sphere, make_uv_sphere(1.0, 32, 16), {}, true);
  s.tube.create();
  s.upload(s.tube, make_unit_tube(32), {}, true);

  glGenVertexArrays(1, &s.stream_vao);
  glGenBuffers(1, &s.stream_vbo);
  glBindVertexArray(s.stream_vao);
  glBindBuffer(GL_ARRAY_BUFFER, s.stream_vbo);
  const auto stride = static_cast<GLsizei>(kUnlitFloats * sizeof(float));
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, byte_offset(0));
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride, byte_offset(3));
  glEnableVertexAttribArray(0);
  glEnableVertexAttribArray(1);
  glBindVertexArray(0);

  const GLenum error = glGetError();
  if (error != GL_NO_ERROR) {
    throw Error(kWhere, "GL error " + std::to_string(error) + " while setting up");
  }
}

Renderer::~Renderer() {
  Impl& s = *impl_;
  for (GpuMesh& m : s.meshes) {
    if (m.vao != 0) {
      m.destroy();
    }
  }
  s.sphere.destroy();
  s.tube.destroy();
  glDeleteBuffers(1, &s.stream_vbo);
  glDeleteVertexArrays(1, &s.stream_vao);
  glDeleteProgram(s.lit_two_sided.id);
  glDeleteProgram(s.lit_one_sided.id);
  glDeleteProgram(s.unlit);
  glDeleteProgram(s.floor);
}

const RenderStats& Renderer::last_frame_stats() const {
  return impl_->stats;
}

std::string Renderer::gl_version() const {
  const auto* version = glGetString(GL_VERSION);
  return version != nullptr ? reinterpret_cast<const char*>(version) : "";
}

void Renderer::draw(const RenderScene& scene, const OrbitCamera& camera, int width_px,
                    int height_px) {
  draw_in(scene, camera, 0, 0, width_px, height_px);
}

void Renderer::draw_in(const RenderScene& scene, const OrbitCamera& camera, int x_px, int y_px,
                       int width_px, int height_px) {
  Impl& s = *impl_;
  const RenderStyle& style = scene.style;
  width_px = std::max(width_px, 1);
  height_px = std::max(height_px, 1);
  glViewport(x_px, y_px, width_px, height_px);
  // Clear only this viewport: a window may draw panels around it.
  glEnable(GL_SCISSOR_TEST);
  glScissor(x_px, y_px, width_px, height_px);
  glClearColor(style.background.x(), style.background.y(), style.background.z(), 1.0f);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glDisable(GL_SCISSOR_TEST);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);  // open sheets and cut meshes are seen from both sides
  glCullFace(GL_BACK);      // closed meshes cull (RenderMesh::closed)
  glDisable(GL_BLEND);
  glEnable(GL_PROGRAM_POINT_SIZE);

  const Eigen::Matrix4d X_camera_world = camera.view_matrix();
  const Eigen::Matrix4d P = camera.projection(static_cast<double>(width_px) / height_px);
  const Eigen::Matrix4f view_projection = (P * X_camera_world).cast<float>();
  const Eigen::Matrix4f projection = P.cast<float>();

  s.sync_meshes(scene);
  s.stats = RenderStats{};

  // Floor and shadow marks share one streamed buffer with the segments: one upload per frame.
  s.staging.clear();
  const RenderFloor& fl = scene.floor;
  const auto floor_first = static_cast<GLint>(s.staging.size() / kUnlitFloats);
  if (fl.visible) {
    const double cx = fl.centre_x_m;
    const double cy = fl.centre_y_m;
    const double e = fl.half_extent_m;
    const Vec3f c = fl.colour_a;
    const Vec3 a(cx - e, cy - e, fl.height_m), b(cx + e, cy - e, fl.height_m),
        d(cx + e, cy + e, fl.height_m), f(cx - e, cy + e, fl.height_m);
    for (const Vec3* corner : {&a, &b, &d, &a, &d, &f}) {
      s.push(*corner, c);
    }
  }
  const auto walls_first = static_cast<GLint>(s.staging.size() / kUnlitFloats);
  if (fl.visible && scene.room.visible) {
    // The two walls on the floor's edges away from the eye: the room's corner behind the scene.
    const Vec3 eye = camera.eye_world();
    const double e = fl.half_extent_m;
    const double x = eye.x() > fl.centre_x_m ? fl.centre_x_m - e : fl.centre_x_m + e;
    const double y = eye.y() > fl.centre_y_m ? fl.centre_y_m - e : fl.centre_y_m + e;
    const double z0 = fl.height_m;
    const double z1 = fl.height_m + scene.room.height_m;
    const Vec3f c = scene.room.colour;
    const Vec3f darker = 0.85f * c;
    const Vec3 a(x, fl.centre_y_m - e, z0), b(x, fl.centre_y_m + e, z0),
        d(x, fl.centre_y_m + e, z1), f(x, fl.centre_y_m - e, z1);
    for (const Vec3* corner : {&a, &b, &d, &a, &d, &f}) {
      s.push(*corner, c);
    }
    const Vec3 g(fl.centre_x_m - e, y, z0), h(fl.centre_x_m + e, y, z0),
        k(fl.centre_x_m + e, y, z1), m(fl.centre_x_m - e, y, z1);
    for (const Vec3* corner : {&g, &h, &k, &g, &k, &m}) {
      s.push(*corner, darker);
    }
  }
  const auto marks_first = static_cast<GLint>(s.staging.size() / kUnlitFloats);
  for (const ShadowMark& mark : scene.shadow_marks) {
    const Vec3 q(mark.point_world.x(), mark.point_world.y(), fl.height_m);
    // Two bars along the floor diagonals, each a rectangle of two triangles.
    constexpr double kHalfSqrt2 = 0.5 * std::numbers::sqrt2;
    for (const Vec3& dir :
         {Vec3(kHalfSqrt2, kHalfSqrt2, 0.0), Vec3(kHalfSqrt2, -kHalfSqrt2, 0.0)}) {
      const Vec3 along = mark.arm_m * dir;
      const Vec3 across = 0.5 * mark.width_m * Vec3(-dir.y(), dir.x(), 0.0);
      const Vec3 p0 = q - along - across, p1 = q + along - across, p2 = q + along + across,
                 p3 = q - along + across;
      for (const Vec3* corner : {&p0, &p1, &p2, &p0, &p2, &p3}) {
        s.push(*corner, mark.colour);
      }
    }
  }
  const auto segments_first = static_cast<GLint>(s.staging.size() / kUnlitFloats);
  for (const RenderSegment& seg : scene.segments) {
    s.push(seg.a_world, seg.colour);
    s.push(seg.b_world, seg.colour);
  }
  const auto stream_end = static_cast<GLint>(s.staging.size() / kUnlitFloats);
  if (stream_end > 0) {
    const std::size_t bytes = s.staging.size() * sizeof(float);
    glBindBuffer(GL_ARRAY_BUFFER, s.stream_vbo);
    if (bytes > s.stream_capacity_bytes) {
      s.stream_capacity_bytes = std::max(bytes, 2 * s.stream_capacity_bytes);
      glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(s.stream_capacity_bytes), nullptr,
                   GL_STREAM_DRAW);
    }
    glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(bytes), s.staging.data());
  }

  glBindVertexArray(s.stream_vao);
  if (walls_first > floor_first) {
    // Pushed back in depth so marks lying exactly on it win the depth test.
    glUseProgram(s.floor);
    set_matrix(s.floor_view_projection, view_projection);
    glUniform1f(s.floor_cell, static_cast<float>(std::max(fl.cell_m, 1e-6)));
    glUniform2f(s.floor_origin, static_cast<float>(fl.centre_x_m),
                static_cast<float>(fl.centre_y_m));
    set_vec3(s.floor_colour_a, fl.colour_a);
    set_vec3(s.floor_colour_b, fl.colour_b);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.0f, 1.0f);
    glDrawArrays(GL_TRIANGLES, floor_first, walls_first - floor_first);
    glDisable(GL_POLYGON_OFFSET_FILL);
  }
  glUseProgram(s.unlit);
  set_matrix(s.unlit_view_projection, view_projection);
  if (marks_first > walls_first) {
    glDrawArrays(GL_TRIANGLES, walls_first, marks_first - walls_first);
  }
  if (segments_first > marks_first) {
    glDrawArrays(GL_TRIANGLES, marks_first, segments_first - marks_first);
  }

  // Meshes and spheres: lit. The frame's uniforms on both variants.
  for (const LitProgram* p : {&s.lit_one_sided, &s.lit_two_sided}) {
    glUseProgram(p->id);
    set_matrix(p->u.projection, projection);
    Impl::set_lit_lighting(p->u, scene.lighting, X_camera_world.topLeftCorner<3, 3>());
    glUniform1f(p->u.point_size, style.point_size_px);
    glUniform1f(p->u.opacity, 1.0f);
  }
  const LitUniforms& lit_u = s.lit_two_sided.u;  // in use from here on, but for closed meshes
  const float line_width = std::clamp(style.line_width_px, 1.0f, s.max_line_width);
  glLineWidth(line_width);
  // Opaque meshes first; see-through ones (opacity < 1) last, blended, not writing depth.
  const Vec3 eye_world = camera.eye_world();
  const auto draw_meshes = [&](bool translucent) {
    GLuint in_use = 0;
    for (MeshId id = 0; id < scene.mesh_count(); ++id) {
      const RenderMesh& m = scene.mesh(id);
      GpuMesh& gpu = s.meshes[id];
      if (!m.visible || gpu.vertex_count == 0 || (m.opacity < 1.0f) != translucent) {
        continue;
      }
      // Faces of a closed surface: its back faces culled and left unlit (points and lines keep
      // every one).
      const bool cull = m.closed() && style.display_mode == DisplayMode::kFaces;
      if (cull) {
        glEnable(GL_CULL_FACE);
      } else {
        glDisable(GL_CULL_FACE);
      }
      const LitProgram& program = cull ? s.lit_one_sided : s.lit_two_sided;
      if (program.id != in_use) {
        glUseProgram(program.id);
        in_use = program.id;
      }
      const LitUniforms& u = program.u;
      glUniform1f(u.opacity, m.opacity);
      set_matrix(u.model_view, (X_camera_world * m.X_world_mesh.matrix()).cast<float>());
      const bool vertex_colours =
          style.colour_mode == ColourMode::kVertexColours && gpu.has_vertex_colours;
      glUniform1i(u.use_vertex_colour, vertex_colours ? 1 : 0);
      set_vec3(u.colour, style.colour_mode == ColourMode::kPalette
                             ? palette_colour(static_cast<int>(id))
                             : m.colour);
      // The level of detail: by the error it would show where the mesh comes nearest the eye.
      std::size_t level = 0;
      if (style.level_of_detail && gpu.level_error_m.size() > 1) {
        const Vec3 centre_world = m.X_world_mesh * m.bounding_centre_M();
        const double distance_m = (centre_world - eye_world).norm() - m.bounding_radius_m();
        const double px_per_m =
            pixels_per_metre(distance_m, camera.near_m(), camera.fov_y_rad, height_px);
        gpu.level =
            select_lod_level(gpu.level_error_m, px_per_m, gpu.level,
                             {style.lod_max_error_px, LodSelectionOptions{}.coarsen_fraction});
        level = gpu.level;
      }
      const GLsizei count = gpu.level_count[level];
      const void* first = byte_offset(static_cast<std::size_t>(gpu.level_first[level]));
      s.stats.triangles_drawn += static_cast<std::size_t>(count / 3);
      s.stats.triangles_full += static_cast<std::size_t>(gpu.level_count[0] / 3);
      s.stats.meshes_coarser += level > 0 ? 1 : 0;
      glBindVertexArray(gpu.vao);
      switch (style.display_mode) {
        case DisplayMode::kPoints:
          glDrawArrays(GL_POINTS, 0, gpu.vertex_count);
          break;
        case DisplayMode::kLines:
          glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
          glDrawElements(GL_TRIANGLES, count, GL_UNSIGNED_INT, first);
          glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
          break;
        case DisplayMode::kFaces:
          glDrawElements(GL_TRIANGLES, count, GL_UNSIGNED_INT, first);
          break;
      }
    }
    glUseProgram(s.lit_two_sided.id);
    glUniform1f(lit_u.opacity, 1.0f);
    glDisable(GL_CULL_FACE);
  };
  draw_meshes(false);

  glUniform1i(lit_u.use_vertex_colour, 0);
  const auto draw_sphere = [&](const Vec3& centre_world, double radius_m, const Vec3f& colour) {
    Eigen::Matrix4d X_world_sphere = Eigen::Matrix4d::Identity();
    X_world_sphere.topLeftCorner<3, 3>() *= radius_m;
    X_world_sphere.topRightCorner<3, 1>() = centre_world;
    set_matrix(lit_u.model_view, (X_camera_world * X_world_sphere).cast<float>());
    set_vec3(lit_u.colour, colour);
    glDrawElements(GL_TRIANGLES, s.sphere.index_count, GL_UNSIGNED_INT, nullptr);
  };
  if (!scene.spheres.empty() || !scene.capsules.empty()) {
    glBindVertexArray(s.sphere.vao);
    for (const RenderSphere& sphere : scene.spheres) {
      if (sphere.wireframe) {
        glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
      }
      draw_sphere(sphere.centre_world, sphere.radius_m, sphere.colour);
      if (sphere.wireframe) {
        glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
      }
    }
    for (const RenderCapsule& c : scene.capsules) {
      draw_sphere(c.a_world, c.radius_m, c.colour);
      draw_sphere(c.b_world, c.radius_m, c.colour);
    }
  }
  if (!scene.capsules.empty()) {
    glBindVertexArray(s.tube.vao);
    for (const RenderCapsule& c : scene.capsules) {
      const Vec3 axis = c.b_world - c.a_world;
      const double length = axis.norm();
      if (!(length > 1e-9)) {
        continue;  // the end spheres are the whole capsule
      }
      // Columns: two unit vectors across the axis, scaled by the radius, and the axis itself.
      const Vec3 z = axis / length;
      const Vec3 x = z.unitOrthogonal();
      const Vec3 y = z.cross(x);
      Eigen::Matrix4d X_world_tube = Eigen::Matrix4d::Identity();
      X_world_tube.block<3, 1>(0, 0) = c.radius_m * x;
      X_world_tube.block<3, 1>(0, 1) = c.radius_m * y;
      X_world_tube.block<3, 1>(0, 2) = axis;
      X_world_tube.topRightCorner<3, 1>() = c.a_world;
      set_matrix(lit_u.model_view, (X_camera_world * X_world_tube).cast<float>());
      set_vec3(lit_u.colour, c.colour);
      glDrawElements(GL_TRIANGLES, s.tube.index_count, GL_UNSIGNED_INT, nullptr);
    }
  }

  if (stream_end > segments_first) {
    glUseProgram(s.unlit);
    glBindVertexArray(s.stream_vao);
    glDrawArrays(GL_LINES, segments_first, stream_end - segments_first);
  }
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glDepthMask(GL_FALSE);
  draw_meshes(true);
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
  glBindVertexArray(0);
  glUseProgram(0);
}

}  // namespace hapsim
