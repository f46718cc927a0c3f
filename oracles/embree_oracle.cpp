// Embree 3 reference: rtcPointQuery over a triangle geometry with a closest-point callback.
//
// Embree is single precision: its BVH is built over float copies of the vertices and traversal
// prunes with a float query sphere. The callback does the point-triangle test in double on the
// original double vertices, so answers are exact in double; the float pruning radius is padded
// by a few float ulps of the scene's size so rounding can never prune the true closest triangle.
// Memory is measured with rtcSetDeviceMemoryMonitorFunction (BVH, float vertex and index
// buffers); the adapter's own double copy of the mesh is not counted. Embree builds with its
// internal thread pool (both cores here), unlike the single-threaded CGAL and FCL builds.
#include "oracles/oracle_factories.h"

#include "hapsim/collision/point_triangle.h"
#include "hapsim/core/stopwatch.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

namespace hapsim::oracle {
namespace {

struct QueryState {
  const TriangleMesh* mesh = nullptr;
  Vec3 p = Vec3::Zero();
  double best_sq = kInf;
  Vec3 best_point = Vec3::Zero();
  std::uint32_t best_triangle = kNoTriangle;
  float pad = 0.0f;  // absolute slack added to the float pruning radius
};

bool closest_point_callback(RTCPointQueryFunctionArguments* args) {
  auto* state = static_cast<QueryState*>(args->userPtr);
  const TriangleIndices& t = state->mesh->triangles[args->primID];
  const std::vector<Vec3>& v = state->mesh->vertices;
  const TriangleClosest c = closest_point_on_triangle(state->p, v[t[0]], v[t[1]], v[t[2]]);
  if (c.distance_sq < state->best_sq) {
    state->best_sq = c.distance_sq;
    state->best_point = c.point;
    state->best_triangle = args->primID;
    const float radius = static_cast<float>(std::sqrt(c.distance_sq)) * (1.0f + 1e-5f) + state->pad;
    if (radius < args->query->radius) {
      args->query->radius = radius;
      return true;
    }
  }
  return false;
}

bool memory_monitor(void* user, ssize_t bytes, bool /*post*/) {
  static_cast<std::atomic<std::int64_t>*>(user)->fetch_add(bytes, std::memory_order_relaxed);
  return true;
}

class EmbreeOracle final : public ClosestPointOracle {
 public:
  explicit EmbreeOracle(const TriangleMesh& mesh) : mesh_(mesh) {
    const Stopwatch watch;
    device_ = rtcNewDevice(nullptr);
    if (device_ == nullptr) {
      throw std::runtime_error("embree: rtcNewDevice failed (error " +
                               std::to_string(static_cast<int>(rtcGetDeviceError(nullptr))) + ")");
    }
    rtcSetDeviceMemoryMonitorFunction(device_, &memory_monitor, &bytes_);
    scene_ = rtcNewScene(device_);
    RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                3 * sizeof(float), mesh_.vertices.size()));
    double max_abs = 0.0;
    for (std::size_t i = 0; i < mesh_.vertices.size(); ++i) {
      const Vec3& x = mesh_.vertices[i];
      vertices[3 * i + 0] = static_cast<float>(x.x());
      vertices[3 * i + 1] = static_cast<float>(x.y());
      vertices[3 * i + 2] = static_cast<float>(x.z());
      max_abs = std::max(max_abs, x.cwiseAbs().maxCoeff());
    }
    auto* indices = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(unsigned), mesh_.triangles.size()));
    static_assert(sizeof(TriangleIndices) == 3 * sizeof(unsigned));
    std::memcpy(indices, mesh_.triangles.data(), mesh_.triangles.size() * sizeof(TriangleIndices));
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(scene_, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(scene_);
    if (const RTCError error = rtcGetDeviceError(device_); error != RTC_ERROR_NONE) {
      throw std::runtime_error("embree: scene build failed (error " +
                               std::to_string(static_cast<int>(error)) + ")");
    }
    build_ms_ = watch.elapsed_ms();
    // Float rounding of vertices (BVH bounds) and of the query point: a few ulps of the largest
    // coordinate (query points lie near the mesh, so its extent bounds theirs).
    state_.mesh = &mesh_;
    state_.pad =
        static_cast<float>(16.0 * static_cast<double>(std::numeric_limits<float>::epsilon()) *
                           std::max(max_abs, 1e-3));
  }

  ~EmbreeOracle() override {
    if (scene_ != nullptr) {
      rtcReleaseScene(scene_);
    }
    if (device_ != nullptr) {
      rtcReleaseDevice(device_);
    }
  }
  EmbreeOracle(const EmbreeOracle&) = delete;
  EmbreeOracle& operator=(const EmbreeOracle&) = delete;

  [[nodiscard]] std::string name() const override { return "embree"; }

  [[nodiscard]] OracleAnswer closest(const Vec3& p) override {
    state_.p = p;
    state_.best_sq = kInf;
    state_.best_triangle = kNoTriangle;
    RTCPointQuery query;
    query.x = static_cast<float>(p.x());
    query.y = static_cast<float>(p.y());
    query.z = static_cast<float>(p.z());
    query.time = 0.0f;
    query.radius = std::numeric_limits<float>::infinity();
    RTCPointQueryContext context;
    rtcInitPointQueryContext(&context);
    rtcPointQuery(scene_, &query, &context, &closest_point_callback, &state_);
    OracleAnswer answer;
    answer.point = state_.best_point;
    answer.distance = std::sqrt(state_.best_sq);
    answer.triangle = state_.best_triangle;
    return answer;
  }

  [[nodiscard]] double build_ms() const override { return build_ms_; }

  [[nodiscard]] std::size_t memory_bytes() const override {
    return static_cast<std::size_t>(std::max<std::int64_t>(0, bytes_.load()));
  }

 private:
  TriangleMesh mesh_;  // double copy: the callback's exact tests use it
  std::atomic<std::int64_t> bytes_{0};
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  QueryState state_;
  double build_ms_ = 0.0;
};

}  // namespace

std::unique_ptr<ClosestPointOracle> make_embree_oracle(const TriangleMesh& mesh) {
  return std::make_unique<EmbreeOracle>(mesh);
}

}  // namespace hapsim::oracle
