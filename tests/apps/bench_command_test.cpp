// The collision benchmark's library (bench/collision_cases.h) run in-process on tiny cases:
// row and JSON schema, workload properties, and a correctness cross-check of every method —
// hapsim's and the reference libraries' — against the exact reference distances.
// Never asserts timings.
#ifdef HAPSIM_HAVE_BENCH_CASES

#include "bench/collision_cases.h"
#include "hapsim/geometry/procedural.h"
#include "oracles/closest_point_oracle.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

namespace hapsim::bench {
namespace {

TEST(CollisionBenchOracles, EveryOracleFindsTheExactClosestPointOnABox) {
  const TriangleMesh box = make_box(Vec3(0.01, 0.02, 0.03));
  struct Case {
    Vec3 p;
    Vec3 closest;
  };
  const Case cases[] = {
      {Vec3(0.05, 0.0, 0.0), Vec3(0.01, 0.0, 0.0)},               // face
      {Vec3(0.02, 0.03, 0.0), Vec3(0.01, 0.02, 0.0)},             // edge
      {Vec3(0.02, 0.03, 0.04), Vec3(0.01, 0.02, 0.03)},           // vertex
      {Vec3(0.0, 0.0, 0.025), Vec3(0.0, 0.0, 0.03)},              // inside, nearest face +z
      {Vec3(-0.004, 0.001, -0.002), Vec3(-0.01, 0.001, -0.002)},  // inside, nearest face -x
  };
  const auto names = oracle::available_oracles();
  if (names.empty()) {
    GTEST_SKIP() << "no reference library (CGAL, FCL, Embree) in this build";
  }
  for (const auto& name : names) {
    auto oracle = oracle::make_oracle(name, box);
    ASSERT_NE(oracle, nullptr) << name;
    EXPECT_EQ(oracle->name(), name);
    EXPECT_GT(oracle->memory_bytes(), 0U) << name;
    EXPECT_GE(oracle->build_ms(), 0.0) << name;
    for (const Case& c : cases) {
      const oracle::OracleAnswer a = oracle->closest(c.p);
      EXPECT_NEAR(a.distance, (c.p - c.closest).norm(), 1e-12) << name << " at " << c.p.transpose();
      // The point must be in the mesh frame (FCL reports per-object frames) and on the box.
      EXPECT_LT((a.point - c.closest).norm(), 1e-12) << name << " at " << c.p.transpose();
      ASSERT_LT(a.triangle, box.triangle_count()) << name;
    }
  }
}

TEST(CollisionBenchOracles, OraclesAgreeOnARandomCloud) {
  const TriangleMesh mesh = make_bumpy_sphere(3000);
  const auto names = oracle::available_oracles();
  if (names.size() < 2) {
    GTEST_SKIP() << "fewer than two reference libraries in this build";
  }
  const auto points = make_workload_points(mesh, Workload::kUniform, 500, 7);
  std::vector<std::unique_ptr<oracle::ClosestPointOracle>> oracles;
  for (const auto& name : names) {
    oracles.push_back(oracle::make_oracle(name, mesh));
  }
  for (const Vec3& p : points) {
    const oracle::OracleAnswer first = oracles.front()->closest(p);
    for (std::size_t k = 1; k < oracles.size(); ++k) {
      const oracle::OracleAnswer other = oracles[k]->closest(p);
      EXPECT_NEAR(other.distance, first.distance, 1e-12)
          << oracles[k]->name() << " vs " << oracles.front()->name() << " at " << p.transpose();
      EXPECT_NEAR((other.point - p).norm(), other.distance, 1e-12) << oracles[k]->name();
    }
  }
}

TEST(CollisionBenchWorkloads, TrajectoryIsSmoothAndNearTheSurface) {
  const TriangleMesh sphere = make_uv_sphere(0.05, 64, 32);
  const auto points = make_workload_points(sphere, Workload::kTrajectory, 3000, 3);
  ASSERT_EQ(points.size(), 3000U);
  double max_step = 0.0;
  double mean_step = 0.0;
  for (std::size_t i = 1; i < points.size(); ++i) {
    const double step = (points[i] - points[i - 1]).norm();
    max_step = std::max(max_step, step);
    mean_step += step / static_cast<double>(points.size() - 1);
  }
  EXPECT_LT(max_step, 0.2e-3);
  EXPECT_GT(mean_step, 0.02e-3);
  EXPECT_LT(mean_step, 0.08e-3);
  for (const Vec3& p : points) {
    // Facets of a 64x32 sphere lie within ~0.3 mm of the true sphere.
    EXPECT_LT(std::abs(p.norm() - 0.05), 5e-3 + 0.5e-3) << p.transpose();
  }
  // Same seed, same points.
  EXPECT_EQ(make_workload_points(sphere, Workload::kTrajectory, 3000, 3), points);
}

TEST(CollisionBenchWorkloads, UniformFillsThePaddedBoundingBox) {
  const TriangleMesh sheet = make_sheet(16, 0.1);
  const auto points = make_workload_points(sheet, Workload::kUniform, 2000, 5);
  double z_min = 0.0;
  double z_max = 0.0;
  for (const Vec3& p : points) {
    EXPECT_LE(std::abs(p.x()), 0.05 + 1e-12);
    EXPECT_LE(std::abs(p.y()), 0.05 + 1e-12);
    z_min = std::min(z_min, p.z());
    z_max = std::max(z_max, p.z());
  }
  EXPECT_LT(z_min, -4e-3);  // the flat sheet's box is padded to ±5 mm
  EXPECT_GT(z_max, 4e-3);
}

TEST(CollisionBench, TinyRunHasTheSchemaAndEveryMethodMatchesTheExactDistances) {
  CollisionBenchOptions options;
  options.meshes = {"sheet-16", "bumpy-13.5k"};
  options.queries = 300;
  options.warmup = 20;
  int progress_calls = 0;
  double last_fraction = -1.0;
  bool monotone = true;
  options.progress = [&](std::string_view, double fraction) {
    ++progress_calls;
    monotone = monotone && fraction >= last_fraction;
    last_fraction = fraction;
  };
  const auto methods = available_methods();
  if (methods.empty()) {
    GTEST_SKIP() << "no query method built";
  }
  const std::vector<CollisionRow> rows = run_collision_bench(options);
  EXPECT_EQ(rows.size(), options.meshes.size() * 2 * methods.size());
  EXPECT_GT(progress_calls, 0);
  EXPECT_TRUE(monotone);
  EXPECT_DOUBLE_EQ(last_fraction, 1.0);

  for (const CollisionRow& row : rows) {
    SCOPED_TRACE(row.mesh + "/" + row.workload + "/" + row.method);
    EXPECT_EQ(row.query_count, 300U);
    EXPECT_GE(row.median_ns, 0.0);
    EXPECT_GE(row.p99_ns, row.median_ns);
    EXPECT_GE(row.build_ms, 0.0);
    EXPECT_GT(row.bytes_per_triangle, 0.0);
    // The cross-check: the same closest distance as the exact reference on every point
    // (contact-radius: the same contact decisions, and the same distance where in contact).
    EXPECT_EQ(row.mismatches, 0U) << "max error " << row.max_distance_error << " m";
    EXPECT_LE(row.max_distance_error, 1e-9);
  }

  const nlohmann::json json = rows_to_json(rows);
  ASSERT_TRUE(json.is_array());
  ASSERT_EQ(json.size(), rows.size());
  const std::set<std::string> workloads{"trajectory", "uniform"};
  const auto all = all_method_names();
  const std::set<std::string> known(all.begin(), all.end());
  for (const auto& row : json) {
    ASSERT_TRUE(row.is_object());
    EXPECT_TRUE(row.at("mesh").is_string());
    EXPECT_TRUE(row.at("triangles").is_number_integer());
    EXPECT_TRUE(workloads.contains(row.at("workload").get<std::string>()));
    EXPECT_TRUE(known.contains(row.at("method").get<std::string>()));
    for (const char* key : {"median_ns", "p99_ns", "build_ms", "bytes_per_triangle"}) {
      EXPECT_TRUE(row.at(key).is_number()) << key;
    }
  }
  // Round trip through text.
  EXPECT_EQ(nlohmann::json::parse(json.dump()), json);

  const std::string table = format_table(rows);
  for (const auto& method : methods) {
    EXPECT_NE(table.find(method), std::string::npos) << method;
  }
  EXPECT_NE(table.find("sheet-16"), std::string::npos);
}

TEST(CollisionBench, RatiosAreRelativeToTheFastestLibrary) {
  std::vector<CollisionRow> rows(3);
  rows[0].mesh = rows[1].mesh = rows[2].mesh = "m";
  rows[0].workload = rows[1].workload = rows[2].workload = "uniform";
  rows[0].method = "hapsim-exact";
  rows[0].median_ns = 50;
  rows[0].p99_ns = 100;
  rows[1].method = "fcl";
  rows[1].median_ns = 200;
  rows[1].p99_ns = 300;
  rows[2].method = "embree";
  rows[2].median_ns = 100;
  rows[2].p99_ns = 400;
  compute_ratios(rows);
  EXPECT_DOUBLE_EQ(rows[0].ratio_to_fastest_library, 0.5);
  EXPECT_DOUBLE_EQ(rows[0].p99_ratio_to_fastest_library, 100.0 / 300.0);
  EXPECT_DOUBLE_EQ(rows[1].ratio_to_fastest_library, 2.0);
  EXPECT_DOUBLE_EQ(rows[2].ratio_to_fastest_library, 1.0);
}

TEST(CollisionBench, UnknownNamesAreUserErrors) {
  EXPECT_ANY_THROW((void)make_bench_mesh("no-such-mesh", std::nullopt));
  const TriangleMesh box = make_box(Vec3(1, 1, 1));
  EXPECT_ANY_THROW((void)make_method("no-such-method", box));
}

}  // namespace
}  // namespace hapsim::bench

#endif  // HAPSIM_HAVE_BENCH_CASES
