// Coverage (core/plan/coverage.cpp) against brute force: a curved sheet
// sampled by scattered points with holes cut out of the sampling, compared
// with a dense uniform sampling of the CAD area whose every sample is
// checked against every point; and the verdicts that follow from it: a
// region whose points were removed is not measured, and the part fails
// unless the plan allows it.
#include "core/plan/coverage.h"

#include <gtest/gtest.h>

#include <random>

#include "core/plan/characteristics.h"
#include "tests/support/test_meshes.h"

namespace surfinspect {
namespace {

double Height(double x, double y) { return 4 * std::sin(x / 9) + 0.05 * y; }

// A sheet over [0, 60]^2 and the error map of ~20k points on it (their
// closest points are themselves), leaving out a disc and a strip.
struct Sheet {
  TriangleMesh mesh;
  ErrorMapResult em;
};

bool Removed(double x, double y) {
  return std::hypot(x - 20, y - 20) < 8 || (x > 40 && x < 52 && y > 5 && y < 55);
}

Sheet MakeSheet() {
  Sheet s;
  s.mesh = testing::HeightField(0, 60, 0, 60, 13, 13, Height);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 60);
  std::vector<Eigen::Vector3f> points;
  for (int k = 0; k < 20000; ++k) {
    const double x = u(rng), y = u(rng);
    if (Removed(x, y)) continue;
    // On the mesh: linear within a cell, so take the triangle's plane via
    // its barycentric interpolation; the cells are 5 mm, Height is smooth.
    const int i = std::min(11, static_cast<int>(x / 5)), j = std::min(11, static_cast<int>(y / 5));
    const double fx = x / 5 - i, fy = y / 5 - j;
    const double z00 = Height(5 * i, 5 * j), z10 = Height(5 * i + 5, 5 * j),
                 z01 = Height(5 * i, 5 * j + 5), z11 = Height(5 * i + 5, 5 * j + 5);
    const double z = fx >= fy ? z00 + fx * (z10 - z00) + fy * (z11 - z10)
                              : z00 + fy * (z01 - z00) + fx * (z11 - z01);
    points.emplace_back(x, y, z);
  }
  auto index = MeshIndex::Build(s.mesh);
  EXPECT_TRUE(index.ok());
  auto em =
      ComputeErrorMap(**index, PointCloud::Unorganized(points), Eigen::Isometry3d::Identity(), {});
  EXPECT_TRUE(em.ok()) << em.status();
  s.em = *std::move(em);
  return s;
}

// Brute force: uniform samples over the area (triangles picked by area,
// uniform inside), each checked against every point.
struct Truth {
  double surface = 0, region = 0;
};
Truth BruteForce(const Sheet& s, double distance, const Eigen::Vector3d& box_min,
                 const Eigen::Vector3d& box_max) {
  std::vector<double> cumulative;
  double total = 0;
  for (const auto& t : s.mesh.triangles) {
    const Eigen::Vector3d a = s.mesh.vertices[t[0]].cast<double>(),
                          b = s.mesh.vertices[t[1]].cast<double>(),
                          c = s.mesh.vertices[t[2]].cast<double>();
    total += 0.5 * (b - a).cross(c - a).norm();
    cumulative.push_back(total);
  }
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  std::size_t hits = 0, in_box = 0, box_hits = 0;
  constexpr int kSamples = 40000;
  for (int k = 0; k < kSamples; ++k) {
    const auto t = static_cast<std::size_t>(
        std::lower_bound(cumulative.begin(), cumulative.end(), u(rng) * total) -
        cumulative.begin());
    const auto& tri = s.mesh.triangles[std::min(t, cumulative.size() - 1)];
    double r1 = u(rng), r2 = u(rng);
    if (r1 + r2 > 1) r1 = 1 - r1, r2 = 1 - r2;
    const Eigen::Vector3d a = s.mesh.vertices[tri[0]].cast<double>();
    const Eigen::Vector3d q = a + r1 * (s.mesh.vertices[tri[1]].cast<double>() - a) +
                              r2 * (s.mesh.vertices[tri[2]].cast<double>() - a);
    bool hit = false;
    for (const Eigen::Vector3f& p : s.em.closest_point)
      if ((p.cast<double>() - q).squaredNorm() <= distance * distance) {
        hit = true;
        break;
      }
    hits += hit;
    // The region is selected by triangle centroid; test the sample's triangle.
    const Eigen::Vector3d centroid =
        (a + s.mesh.vertices[tri[1]].cast<double>() + s.mesh.vertices[tri[2]].cast<double>()) / 3;
    if ((centroid.array() >= box_min.array()).all() &&
        (centroid.array() <= box_max.array()).all()) {
      ++in_box;
      box_hits += hit;
    }
  }
  return {static_cast<double>(hits) / kSamples, static_cast<double>(box_hits) / in_box};
}

TEST(Coverage, EqualsADenseBruteForceSamplingOfTheArea) {
  const Sheet s = MakeSheet();
  InspectionPlan plan;
  PlanRegion hole{"around_the_disc", {}, {}, 0, {}};
  hole.select.box_min_mm = {5, 5, -10};
  hole.select.box_max_mm = {35, 35, 10};
  plan.regions = {hole};
  auto rp = ResolveInspectionPlan(plan, s.mesh);
  ASSERT_TRUE(rp.ok()) << rp.status();
  CoverageSettings cs;
  cs.distance_mm = 0.8;  // the points are ~0.42 mm apart on average
  auto got = ComputeCoverage(s.em, s.mesh, *rp, cs);
  ASSERT_TRUE(got.ok()) << got.status();
  const Truth truth = BruteForce(s, cs.distance_mm, hole.select.box_min_mm, hole.select.box_max_mm);
  std::cout << "surface " << got->surface << " (brute force " << truth.surface << "), region "
            << got->regions[0] << " (" << truth.region << ")\n";
  EXPECT_NEAR(got->surface, truth.surface, 0.01);
  EXPECT_NEAR(got->regions[0], truth.region, 0.01);
  EXPECT_LT(got->surface, 0.85) << "the disc and the strip are ~19% of the area";
  EXPECT_EQ(got->triangles.size(), s.mesh.num_triangles());
  // The same for any thread count.
  cs.threads = 1;
  auto one = ComputeCoverage(s.em, s.mesh, *rp, cs);
  ASSERT_TRUE(one.ok());
  EXPECT_EQ(one->triangles, got->triangles);
  EXPECT_EQ(one->surface, got->surface);
}

// A sheet folded at 90 degrees along x = 0: the top scanned only from 3 mm
// off the fold. No point lies within reach of the flange, so it is not
// covered; a point projected onto the flange's plane would land on its
// edge and cover a strip there if every neighbour's points were taken.
TEST(Coverage, APointBeyondAFoldDoesNotCoverTheOtherFace) {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {0, 10, 0}, {0, 0, -10}, {0, 10, -10}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 3, 5}, {0, 5, 4}};
  std::vector<Eigen::Vector3f> points;
  for (float x = 3; x <= 10; x += 0.25f)
    for (float y = 0; y <= 10; y += 0.25f) points.emplace_back(x, y, 0.f);
  auto index = MeshIndex::Build(mesh);
  ASSERT_TRUE(index.ok());
  auto em =
      ComputeErrorMap(**index, PointCloud::Unorganized(points), Eigen::Isometry3d::Identity(), {});
  ASSERT_TRUE(em.ok()) << em.status();
  auto rp = ResolveInspectionPlan(InspectionPlan{}, mesh);
  ASSERT_TRUE(rp.ok());
  CoverageSettings cs;
  cs.distance_mm = 0.8;
  auto got = ComputeCoverage(*em, mesh, *rp, cs);
  ASSERT_TRUE(got.ok()) << got.status();
  EXPECT_EQ(got->triangles[2], 0.f);
  EXPECT_EQ(got->triangles[3], 0.f);
  // The top is seen from x = 3 - 0.8 on: (10 - 2.2) / 10 of it.
  EXPECT_NEAR(0.5 * (got->triangles[0] + got->triangles[1]), 0.78, 0.02);
}

TEST(Coverage, AComparisonPointCountsTheSurfaceWithinItsRadius) {
  const Sheet s = MakeSheet();
  InspectionPlan plan;
  ComparisonPoint in_disc{"in_disc", {20, 20, Height(20, 20)}, Eigen::Vector3d::Zero(), 3.0, {},
                          {}};
  ComparisonPoint on_edge{"on_edge", {28, 20, Height(28, 20)}, Eigen::Vector3d::Zero(), 3.0, {},
                          {}};
  ComparisonPoint seen{"seen", {10, 45, Height(10, 45)}, Eigen::Vector3d::Zero(), 3.0, {}, {}};
  plan.points = {in_disc, on_edge, seen};
  auto rp = ResolveInspectionPlan(plan, s.mesh);
  ASSERT_TRUE(rp.ok());
  CoverageSettings cs;
  cs.distance_mm = 0.8;
  auto got = ComputeCoverage(s.em, s.mesh, *rp, cs);
  ASSERT_TRUE(got.ok());
  EXPECT_EQ(got->points[0], 0.0) << "5 mm inside the 8 mm disc";
  EXPECT_GT(got->points[1], 0.3);  // half its disc lies outside the hole
  EXPECT_LT(got->points[1], 0.7);
  EXPECT_GT(got->points[2], 0.97);
  // A disc smaller than the sampling cells still has samples.
  plan.points = {seen};
  plan.points[0].radius_mm = 0.3;
  rp = ResolveInspectionPlan(plan, s.mesh);
  ASSERT_TRUE(rp.ok());
  cs.distance_mm = 4;  // cells of 2 mm
  got = ComputeCoverage(s.em, s.mesh, *rp, cs);
  ASSERT_TRUE(got.ok());
  EXPECT_EQ(got->points[0], 1.0);
}

TEST(Coverage, ARegionWhosePointsWereRemovedIsNotMeasured) {
  const Sheet s = MakeSheet();
  InspectionPlan plan;
  plan.tolerance = {-0.1, 0.1};
  PlanRegion strip{"strip", {}, {}, 0, {}};  // inside the removed strip but a rim
  strip.select.box_min_mm = {40, 0, -10};
  strip.select.box_max_mm = {55, 60, 10};
  PlanRegion seen{"seen", {}, {}, 0, {}};
  seen.select.box_min_mm = {0, 35, -10};
  seen.select.box_max_mm = {35, 60, 10};
  plan.regions = {strip, seen};
  plan.min_coverage = 0.7;
  auto rp = ResolveInspectionPlan(plan, s.mesh);
  ASSERT_TRUE(rp.ok());
  CoverageSettings cs;
  cs.distance_mm = 0.8;
  auto coverage = ComputeCoverage(s.em, s.mesh, *rp, cs);
  ASSERT_TRUE(coverage.ok());
  auto judged = ComputeCharacteristics(s.em, *rp, 0, {}, &*coverage);
  ASSERT_TRUE(judged.ok()) << judged.status();
  const auto& c = judged->characteristics;
  ASSERT_EQ(c.size(), 3u);
  EXPECT_TRUE(c[0].measured) << c[0].reason;  // the surface: ~80% seen
  EXPECT_FALSE(c[1].measured);
  EXPECT_FALSE(c[1].pass);
  EXPECT_GT(c[1].points, 0u) << "a rim of points is not enough";
  EXPECT_STREQ(VerdictName(c[1]), "not_measured");
  EXPECT_EQ(c[1].reason.rfind("not measured:", 0), 0u) << c[1].reason;
  EXPECT_TRUE(c[2].pass) << c[2].reason;
  EXPECT_FALSE(judged->pass) << "not measured fails the part";
  EXPECT_EQ(judged->failed, 0u);
  EXPECT_EQ(judged->not_measured, 1u);
  // Allowed by the plan: the part passes, the region still says so.
  rp->plan.allow_not_measured = true;
  judged = ComputeCharacteristics(s.em, *rp, 0, {}, &*coverage);
  ASSERT_TRUE(judged.ok());
  EXPECT_TRUE(judged->pass) << judged->reason;
  EXPECT_STREQ(VerdictName(judged->characteristics[1]), "not_measured");
  // Without coverage nothing is judged on it.
  EXPECT_TRUE(ComputeCharacteristics(s.em, *rp, 0, {})->characteristics[1].measured);
}

TEST(Coverage, ADegenerateTriangleWeighsNothing) {
  Sheet s = MakeSheet();
  auto rp = ResolveInspectionPlan(InspectionPlan{}, s.mesh);
  ASSERT_TRUE(rp.ok());
  CoverageSettings cs;
  cs.distance_mm = 0.8;
  auto before = ComputeCoverage(s.em, s.mesh, *rp, cs);
  ASSERT_TRUE(before.ok());
  const auto v = static_cast<uint32_t>(s.mesh.vertices.size());
  s.mesh.vertices.insert(s.mesh.vertices.end(), {{1, 1, 0}, {2, 2, 0}, {3, 3, 0}});  // collinear
  s.mesh.triangles.push_back({v, v + 1, v + 2});
  rp = ResolveInspectionPlan(InspectionPlan{}, s.mesh);
  ASSERT_TRUE(rp.ok());
  auto after = ComputeCoverage(s.em, s.mesh, *rp, cs);
  ASSERT_TRUE(after.ok()) << after.status();
  EXPECT_EQ(after->surface, before->surface);
  EXPECT_EQ(after->triangles.back(), 0.f);
}

TEST(Coverage, RefusesBadSettings) {
  const Sheet s = MakeSheet();
  auto rp = ResolveInspectionPlan(InspectionPlan{}, s.mesh);
  ASSERT_TRUE(rp.ok());
  CoverageSettings cs;
  cs.distance_mm = 0;
  EXPECT_EQ(ComputeCoverage(s.em, s.mesh, *rp, cs).status().code(),
            absl::StatusCode::kInvalidArgument);
  cs.distance_mm = 1;
  EXPECT_FALSE(ComputeCoverage(s.em, testing::FlatSquare(), *rp, cs).ok());
}

}  // namespace
}  // namespace surfinspect
