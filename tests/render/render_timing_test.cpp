// Not a check: times a viewer-sized frame (run with --gtest_also_run_disabled_tests). Optionally
// writes the last frame to $HAPSIM_RENDER_PNG for a look.
#include "hapsim/geometry/procedural.h"
#include "hapsim/render/png_image.h"
#include "hapsim/render/renderer.h"
#include "render/gl_test_context.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>

namespace hapsim {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

TEST(RenderTiming, DISABLED_Frame1280x720Of14kVertexMesh) {
  for (const int samples : {1, 4}) {
    auto maybe = test::make_test_context(1280, 720, samples);
    if (!maybe.context) {
      GTEST_SKIP() << maybe.why_not;
    }
    OffscreenContext& ctx = *maybe.context;
    Renderer renderer;
    RenderScene scene;
    const TriangleMesh body = make_bumpy_sphere(28000, 0.05);
    const MeshId id =
        scene.add_mesh(body, Vec3f(0.85f, 0.75f, 0.65f), Iso3(Eigen::Translation3d(0, 0, 0.06)));
    scene.floor.half_extent_m = 0.2;
    scene.floor.cell_m = 0.02;
    scene.spheres.push_back({Vec3(0.02, 0.03, 0.13), 0.006, Vec3f(0.9f, 0.3f, 0.2f), false});
    scene.spheres.push_back({Vec3(0, 0, 0.06), 0.06, Vec3f(0.3f, 0.8f, 0.3f), true});
    scene.segments.push_back({Vec3(0.02, 0.03, 0.13), Vec3(0.02, 0.03, 0.2), Vec3f(1, 1, 0)});
    scene.shadow_marks.push_back({Vec3(0.02, 0.03, 0.13), 0.008, 0.002, Vec3f(0.1f, 0.1f, 0.1f)});
    OrbitCamera cam;
    cam.yaw_rad = 0.6;
    cam.pitch_rad = 0.5;
    cam.frame(scene.bounds_W(), 1280.0 / 720.0);

    std::vector<std::uint8_t> rgba;
    std::vector<Vec3> moved = body.vertices;
    renderer.draw(scene, cam, 1280, 720);  // warm-up: upload, shader JIT
    ctx.read_rgba(rgba);
    const int frames = 20;
    double draw_ms = 0.0, read_ms = 0.0, update_ms = 0.0, dynamic_ms = 0.0;
    for (int f = 0; f < frames; ++f) {
      cam.rotate(5.0, 0.0);
      auto t0 = Clock::now();
      renderer.draw(scene, cam, 1280, 720);
      glFinish();
      draw_ms += ms_since(t0);
      t0 = Clock::now();
      ctx.read_rgba(rgba);
      read_ms += ms_since(t0);
      // Deforming body: new positions, normals on the CPU, re-upload, draw.
      for (std::size_t i = 0; i < moved.size(); ++i) {
        moved[i] = body.vertices[i] * (1.0 + 0.02 * std::sin(0.3 * f + moved[i].x() * 100.0));
      }
      t0 = Clock::now();
      scene.update_positions(id, moved);
      update_ms += ms_since(t0);
      t0 = Clock::now();
      renderer.draw(scene, cam, 1280, 720);
      glFinish();
      dynamic_ms += ms_since(t0);
    }
    std::printf(
        "%s, %d samples, %zu vertices / %zu triangles at 1280x720: draw %.1f ms, read_rgba %.1f "
        "ms, update_positions %.1f ms, draw after update %.1f ms (mean of %d)\n",
        ctx.renderer_name().c_str(), ctx.samples(), body.vertex_count(), body.triangle_count(),
        draw_ms / frames, read_ms / frames, update_ms / frames, dynamic_ms / frames, frames);
    if (const char* path = std::getenv("HAPSIM_RENDER_PNG"); path != nullptr) {
      write_png(std::string(path) + "_" + std::to_string(samples) + ".png", 1280, 720, rgba);
    }
  }
}

}  // namespace
}  // namespace hapsim
