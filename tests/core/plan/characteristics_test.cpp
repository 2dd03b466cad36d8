#include "core/plan/characteristics.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <iostream>
#include <nlohmann/json.hpp>
#include <random>

#include "tests/support/test_meshes.h"

namespace surfinspect {
namespace {

// z = 0 over [0, 100]^2, 200 triangles.
TriangleMesh Plane() {
  return testing::HeightField(0, 100, 0, 100, 11, 11, [](double, double) { return 0.0; });
}

// `n` points above the plane with Gaussian heights, a few NaN pixels and a
// few beyond max_distance, through the real error map.
ErrorMapResult RandomMap(const MeshIndex& index, std::size_t n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(0.5f, 99.5f);
  std::normal_distribution<float> g(0.01f, 0.06f);
  std::vector<Eigen::Vector3f> pts;
  for (std::size_t i = 0; i < n; ++i) {
    const float z = i % 997 == 0 ? 9.0f : g(rng);
    pts.emplace_back(u(rng), u(rng), i % 1009 == 0 ? NAN : z);
  }
  auto r = ComputeErrorMap(index, PointCloud::Unorganized(pts), Eigen::Isometry3d::Identity(), {});
  EXPECT_TRUE(r.ok()) << r.status();
  return *std::move(r);
}

InspectionPlan RandomPlan(const TriangleMesh& m) {
  InspectionPlan plan;
  plan.tolerance = {-0.08, 0.12};
  plan.allowed_fraction_outside = 0.2;
  PlanRegion box{"box", {}, ToleranceBand{-0.05, 0.15}, 0.1, {}};
  box.select.box_min_mm = {10, 10, -1};
  box.select.box_max_mm = {60, 45, 1};
  PlanRegion overlap{"overlap", {}, {}, 0.0, {}};
  overlap.select.box_min_mm = {40, 0, -1};
  overlap.select.box_max_mm = {100, 100, 1};
  PlanRegion picked{"picked", {}, ToleranceBand{-0.2, 0.0}, 0.5, {}};
  picked.select.kind = RegionSelector::Kind::kTriangles;
  for (uint32_t t = 0; t < m.num_triangles(); t += 7) picked.select.triangles.push_back(t);
  plan.regions = {box, overlap, picked};
  plan.points = {{"P1", {50, 50, 0}, {}, 2.0, ToleranceBand{-0.01, 0.03}, {}},
                 {"P2", {10, 90, 0.5}, {}, 3.5, {}, {}},
                 {"corner", {0, 0, 0}, {}, 3.0, {}, {}},
                 {"off", {50, 50, 10}, {}, 2.0, {}, {}}};  // no CAD point within 2 mm: unmeasured
  return plan;
}

// Two-pass statistics in double over the selected matched deviations.
struct Direct {
  std::size_t n = 0, within = 0, above = 0, below = 0;
  double min = INFINITY, max = -INFINITY, mean = NAN, stddev = NAN, rms = NAN;
};
template <typename Select>
Direct DirectStats(const ErrorMapResult& em, const ToleranceBand& band, Select select) {
  Direct d;
  std::vector<double> v;
  for (std::size_t i = 0; i < em.deviation_mm.size(); ++i)
    if (em.triangle_id[i] != UINT32_MAX && select(i)) {
      const float x = em.deviation_mm[i];
      v.push_back(x);
      if (band.Contains(x))
        ++d.within;
      else if (x > static_cast<float>(band.upper_mm))
        ++d.above;
      else
        ++d.below;
    }
  d.n = v.size();
  if (v.empty()) return d;
  double sum = 0, sum2 = 0;
  for (double x : v)
    sum += x, sum2 += x * x, d.min = std::min(d.min, x), d.max = std::max(d.max, x);
  d.mean = sum / v.size();
  double var = 0;
  for (double x : v) var += (x - d.mean) * (x - d.mean);
  d.stddev = std::sqrt(var / v.size());
  d.rms = std::sqrt(sum2 / v.size());
  return d;
}

void ExpectMatches(const CharacteristicResult& c, const Direct& d) {
  EXPECT_EQ(c.points, d.n) << c.name;
  EXPECT_EQ(c.within, d.within) << c.name;
  EXPECT_EQ(c.above, d.above) << c.name;
  EXPECT_EQ(c.below, d.below) << c.name;
  if (d.n == 0) return;
  EXPECT_EQ(c.min_mm, d.min) << c.name;
  EXPECT_EQ(c.max_mm, d.max) << c.name;
  EXPECT_NEAR(c.mean_mm, d.mean, 1e-14) << c.name;
  EXPECT_NEAR(c.stddev_mm, d.stddev, 1e-12) << c.name;
  EXPECT_NEAR(c.rms_mm, d.rms, 1e-14) << c.name;
  EXPECT_EQ(c.fraction_within, static_cast<double>(d.within) / d.n) << c.name;
}

TEST(Characteristics, RegionsAndPointsEqualBruteForce) {
  const TriangleMesh m = Plane();
  auto index = MeshIndex::Build(m);
  ASSERT_TRUE(index.ok());
  const ErrorMapResult em = RandomMap(**index, 50000, 7);
  const InspectionPlan plan = RandomPlan(m);
  auto rp = ResolveInspectionPlan(plan, m);
  ASSERT_TRUE(rp.ok()) << rp.status();
  auto r = ComputeCharacteristics(em, *rp);
  ASSERT_TRUE(r.ok()) << r.status();
  ASSERT_EQ(r->characteristics.size(), 1 + 3 + 4);

  const CharacteristicResult& surface = r->characteristics[0];
  EXPECT_EQ(surface.name, "surface");
  EXPECT_EQ(surface.type, CharacteristicType::kSurface);
  ExpectMatches(surface, DirectStats(em, plan.tolerance, [](std::size_t) { return true; }));
  EXPECT_EQ(surface.mean_mm, em.stats.mean_mm) << "the error map's own statistics";
  EXPECT_EQ(surface.points, em.stats.matched);
  // A plan with neither regions nor points (the default) skips the lookups
  // by triangle: the same surface.
  InspectionPlan bare;
  bare.tolerance = plan.tolerance;
  auto rb = ResolveInspectionPlan(bare, m);
  ASSERT_TRUE(rb.ok()) << rb.status();
  EXPECT_TRUE(rb->region_ids.empty() && rb->point_ids.empty());
  EXPECT_EQ(rb->region_offsets.size(), m.num_triangles() + 1);
  auto only_surface = ComputeCharacteristics(em, *rb);
  ASSERT_TRUE(only_surface.ok()) << only_surface.status();
  ASSERT_EQ(only_surface->characteristics.size(), 1u);
  ExpectMatches(only_surface->characteristics[0],
                DirectStats(em, plan.tolerance, [](std::size_t) { return true; }));

  // Region membership by brute force: the closest triangle's centroid in the
  // box, or its id in the list.
  auto centroid = [&](uint32_t t) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) c += m.vertices[m.triangles[t][k]].cast<double>() / 3;
    return c;
  };
  for (std::size_t k = 0; k < plan.regions.size(); ++k) {
    const PlanRegion& region = plan.regions[k];
    const Direct d = DirectStats(em, region.tolerance.value_or(plan.tolerance), [&](std::size_t i) {
      const uint32_t t = em.triangle_id[i];
      if (region.select.kind == RegionSelector::Kind::kTriangles) return t % 7 == 0;
      const Eigen::Vector3d c = centroid(t);
      return (c.array() >= region.select.box_min_mm.array()).all() &&
             (c.array() <= region.select.box_max_mm.array()).all();
    });
    EXPECT_GT(d.n, 1000u);
    const CharacteristicResult& c = r->characteristics[1 + k];
    EXPECT_EQ(c.name, region.name);
    EXPECT_EQ(c.type, CharacteristicType::kRegion);
    ExpectMatches(c, d);
    EXPECT_EQ(c.pass, 1 - c.fraction_within <= region.allowed_fraction_outside) << c.name;
  }
  // Comparison points: the mean over the points whose closest CAD point is
  // within the radius, by a full scan.
  for (std::size_t k = 0; k < plan.points.size(); ++k) {
    const ComparisonPoint& p = plan.points[k];
    const ToleranceBand band = p.tolerance.value_or(plan.tolerance);
    const Direct d = DirectStats(em, band, [&](std::size_t i) {
      return (em.closest_point[i].cast<double>() - p.position_mm).norm() <= p.radius_mm;
    });
    const CharacteristicResult& c = r->characteristics[4 + k];
    EXPECT_EQ(c.name, p.name);
    EXPECT_EQ(c.type, CharacteristicType::kPoint);
    ExpectMatches(c, d);
    if (p.name == "off") {
      EXPECT_EQ(c.points, 0u);
      EXPECT_TRUE(std::isnan(c.value_mm));
      EXPECT_FALSE(c.pass);
      EXPECT_NE(c.reason.find("unmeasured"), std::string::npos) << c.reason;
    } else {
      EXPECT_GT(d.n, 10u) << p.name;
      EXPECT_EQ(c.value_mm, c.mean_mm);
      EXPECT_EQ(c.pass, band.Contains(static_cast<float>(d.mean))) << p.name;
    }
  }
  EXPECT_FALSE(r->pass) << "the unmeasured point fails the part";
  EXPECT_GE(r->failed, 1u);
}

TEST(Characteristics, SameResultForAnyThreadCount) {
  const TriangleMesh m = Plane();
  auto index = MeshIndex::Build(m);
  ASSERT_TRUE(index.ok());
  const ErrorMapResult em = RandomMap(**index, 300000, 11);  // several chunks
  auto rp = ResolveInspectionPlan(RandomPlan(m), m);
  ASSERT_TRUE(rp.ok());
  CharacteristicsSettings one, two;
  one.threads = 1;
  two.threads = 2;
  auto a = ComputeCharacteristics(em, *rp, 0, one);
  auto b = ComputeCharacteristics(em, *rp, 0, two);
  ASSERT_TRUE(a.ok() && b.ok());
  for (std::size_t k = 0; k < a->characteristics.size(); ++k) {
    const auto &x = a->characteristics[k], &y = b->characteristics[k];
    EXPECT_EQ(x.points, y.points);
    EXPECT_EQ(std::memcmp(&x.mean_mm, &y.mean_mm, sizeof(double)), 0) << x.name;
    EXPECT_EQ(std::memcmp(&x.stddev_mm, &y.stddev_mm, sizeof(double)), 0) << x.name;
    EXPECT_EQ(std::memcmp(&x.rms_mm, &y.rms_mm, sizeof(double)), 0) << x.name;
    EXPECT_EQ(x.reason, y.reason);
  }
}

// A hand-made error map on two triangles (0: the lower-left half of the
// unit square, 1: the upper-right), deviations given per point.
struct HandMade {
  TriangleMesh mesh;
  ErrorMapResult em;
};
HandMade TwoTriangles(const std::vector<float>& on0, const std::vector<float>& on1) {
  HandMade h;
  h.mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  h.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  auto add = [&](float d, uint32_t t) {
    h.em.deviation_mm.push_back(d);
    h.em.triangle_id.push_back(t);
    h.em.closest_point.emplace_back(t == 0 ? 0.7f : 0.3f, t == 0 ? 0.3f : 0.7f, 0.0f);
  };
  for (float d : on0) add(d, 0);
  for (float d : on1) add(d, 1);
  return h;
}

TEST(Characteristics, AsymmetricBandEdgesGiveTheRightVerdicts) {
  // Band [-0.05, 0.15]: the edges themselves are inside, the next float
  // outward is outside.
  const float lo = -0.05f, hi = 0.15f;
  const float below = std::nextafter(lo, -1.0f), above = std::nextafter(hi, 1.0f);
  HandMade h = TwoTriangles({lo, hi, 0.0f, 0.1f}, {below, above, hi, lo});
  InspectionPlan plan;
  plan.tolerance = {-0.05, 0.15};
  PlanRegion a{"edges", {}, {}, 0.0, {}};
  a.select.kind = RegionSelector::Kind::kTriangles;
  a.select.triangles = {0};
  PlanRegion b{"beyond", {}, {}, 0.5, {}};
  b.select.kind = RegionSelector::Kind::kTriangles;
  b.select.triangles = {1};
  PlanRegion c = b;
  c.name = "beyond_strict";
  c.allowed_fraction_outside = 0.49;
  plan.regions = {a, b, c};
  // Points: the mean of triangle 0's points (0.05), judged against bands
  // whose upper edge is the value itself and just below it.
  plan.points = {{"at_edge", {0.7, 0.3, 0}, {}, 0.01, ToleranceBand{-0.01, 0.05}, {}},
                 {"past_edge", {0.7, 0.3, 0}, {}, 0.01, ToleranceBand{-0.01, 0.0499}, {}},
                 {"lower_edge", {0.7, 0.3, 0}, {}, 0.01, ToleranceBand{0.05, 0.2}, {}}};
  auto rp = ResolveInspectionPlan(plan, h.mesh);
  ASSERT_TRUE(rp.ok()) << rp.status();
  auto r = ComputeCharacteristics(h.em, *rp);
  ASSERT_TRUE(r.ok()) << r.status();
  const auto& ch = r->characteristics;
  EXPECT_EQ(ch[1].within, 4u);
  EXPECT_TRUE(ch[1].pass) << ch[1].reason;
  EXPECT_EQ(ch[2].within, 2u);
  EXPECT_EQ(ch[2].above, 1u);
  EXPECT_EQ(ch[2].below, 1u);
  EXPECT_TRUE(ch[2].pass) << "2 of 4 outside, 50% allowed: " << ch[2].reason;
  EXPECT_FALSE(ch[3].pass) << "2 of 4 outside, 49% allowed: " << ch[3].reason;
  EXPECT_EQ(ch[0].within, 6u);
  EXPECT_FALSE(ch[0].pass) << "strict surface";
  const double mean0 = (double{lo} + double{hi} + 0.0 + double{0.1f}) / 4;
  EXPECT_NEAR(ch[4].value_mm, mean0, 1e-15);
  EXPECT_EQ(ch[4].points, 4u);
  EXPECT_TRUE(ch[4].pass) << ch[4].reason;
  EXPECT_FALSE(ch[5].pass) << ch[5].reason;
  EXPECT_TRUE(ch[6].pass) << ch[6].reason;
  EXPECT_FALSE(r->pass);
}

TEST(Characteristics, DefectsFailThePartOnlyWithMaxCount) {
  HandMade h = TwoTriangles({0.0f, 0.01f}, {-0.01f});
  h.em.stats.matched = 3;
  InspectionPlan plan;
  plan.defects = DefectRules{};
  auto rp = ResolveInspectionPlan(plan, h.mesh);
  ASSERT_TRUE(rp.ok());
  auto r = ComputeCharacteristics(h.em, *rp, 5);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r->pass) << r->reason;
  plan.defects->max_count = 5;
  rp = ResolveInspectionPlan(plan, h.mesh);
  EXPECT_TRUE(ComputeCharacteristics(h.em, *rp, 5)->pass);
  EXPECT_FALSE(ComputeCharacteristics(h.em, *rp, 6)->pass);
  plan.defects->max_count = 0;
  rp = ResolveInspectionPlan(plan, h.mesh);
  auto zero = ComputeCharacteristics(h.em, *rp, 1);
  EXPECT_FALSE(zero->pass);
  EXPECT_NE(zero->reason.find("1 defects (at most 0 allowed)"), std::string::npos) << zero->reason;
}

// Directional points on the slope z = 0.5 x, scanned 0.2 mm too high
// (every point shifted along +z): the normal deviation is 0.2 cos(atan 0.5)
// = 0.1789 mm; along the stamping direction +z it is the 0.2 mm shift;
// along +x the surface is met 0.4 mm behind (0.5 (x + t) + 0.2 = 0.5 x);
// a direction in the face's plane cannot meet it and gives no value.
TEST(Characteristics, ADirectionalPointMeasuresAlongItsDirection) {
  const TriangleMesh mesh =
      testing::HeightField(0, 40, 0, 40, 5, 5, [](double x, double) { return 0.5 * x; });
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i <= 160; ++i)
    for (int j = 0; j <= 160; ++j) {
      const double x = 0.25 * i, y = 0.25 * j;
      points.emplace_back(x, y, 0.5 * x + 0.2);
    }
  auto index = MeshIndex::Build(mesh);
  ASSERT_TRUE(index.ok());
  auto em =
      ComputeErrorMap(**index, PointCloud::Unorganized(points), Eigen::Isometry3d::Identity(), {});
  ASSERT_TRUE(em.ok());
  InspectionPlan plan;
  plan.tolerance = {-1, 1};
  const Eigen::Vector3d at(20, 20, 10);
  ComparisonPoint normal{"normal", at, Eigen::Vector3d::Zero(), 2.0, {}, {}};
  ComparisonPoint up = normal, along_x = normal, in_plane = normal;
  up.name = "up";
  up.direction = Eigen::Vector3d::UnitZ();
  along_x.name = "along_x";
  along_x.direction = Eigen::Vector3d::UnitX();
  in_plane.name = "in_plane";
  in_plane.direction = Eigen::Vector3d(2, 0, 1).normalized();
  plan.points = {normal, up, along_x, in_plane};
  auto rp = ResolveInspectionPlan(plan, mesh);
  ASSERT_TRUE(rp.ok()) << rp.status();
  auto r = ComputeCharacteristics(*em, *rp);
  ASSERT_TRUE(r.ok());
  const auto& c = r->characteristics;
  EXPECT_NEAR(c[1].value_mm, 0.2 / std::sqrt(1.25), 1e-5);
  EXPECT_NEAR(c[2].value_mm, 0.2, 1e-5);
  EXPECT_NEAR(c[3].value_mm, -0.4, 1e-5);
  EXPECT_NE(c[2].reason.find("along (0, 0, 1)"), std::string::npos) << c[2].reason;
  EXPECT_EQ(c[4].points, 0u);
  EXPECT_FALSE(c[4].pass);
  EXPECT_NE(c[4].reason.find("the direction can meet"), std::string::npos) << c[4].reason;
  // The JSON form: a zero direction is refused, naming the field.
  auto bad = ParseInspectionPlan(
      nlohmann::json::parse(R"({"points": [{"name": "P", "position_mm": [20, 20, 10],
                                            "direction": [0, 0, 0]}]})"),
      mesh);
  EXPECT_EQ(bad.status().message(), "plan.points[0].direction: zero vector");
}

TEST(Characteristics, RefusesAMapFromAnotherMesh) {
  HandMade h = TwoTriangles({0.0f}, {0.0f});
  h.em.triangle_id[1] = 7;
  auto rp = ResolveInspectionPlan(InspectionPlan{}, h.mesh);
  ASSERT_TRUE(rp.ok());
  EXPECT_EQ(ComputeCharacteristics(h.em, *rp).status().code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace surfinspect
