// Sections (core/plan/section.cpp) against independent oracles: the pillar
// cut across its length is its hat profile (the same length as a ring of
// the extrusion), a sphere cut through its centre is one closed loop, the
// crossed triangles are counted directly, and the points and statistics
// equal a brute-force selection of the points within +-width/2.
#include "core/plan/section.h"

#include <gtest/gtest.h>

#include <random>

#include "core/simulation/demo_cell.h"
#include "tests/support/test_meshes.h"

namespace surfinspect {
namespace {

double Length(const std::vector<Eigen::Vector3d>& line) {
  double l = 0;
  for (std::size_t k = 1; k < line.size(); ++k) l += (line[k] - line[k - 1]).norm();
  return l;
}

// A random triangle of `mesh` and a uniform random point on it.
std::pair<uint32_t, Eigen::Vector3f> RandomSurfacePoint(const TriangleMesh& mesh,
                                                        std::mt19937_64& rng) {
  std::uniform_int_distribution<uint32_t> tri(0, static_cast<uint32_t>(mesh.num_triangles() - 1));
  std::uniform_real_distribution<double> u(0, 1);
  const uint32_t t = tri(rng);
  double a = u(rng), b = u(rng);
  if (a + b > 1) a = 1 - a, b = 1 - b;
  const auto& v = mesh.triangles[t];
  const Eigen::Vector3f p0 = mesh.vertices[v[0]];
  return {t, p0 + static_cast<float>(a) * (mesh.vertices[v[1]] - p0) +
                 static_cast<float>(b) * (mesh.vertices[v[2]] - p0)};
}

TEST(Section, ThePillarCutAcrossIsItsProfile) {
  const TriangleMesh pillar = MakePillarMesh(300);
  // Rings of the extrusion every 5 mm from x = -150: 61 rings.
  const std::size_t np = pillar.vertices.size() / 61;
  ASSERT_EQ(np * 61, pillar.vertices.size());
  double ring = 0;  // the ring at x = 10 (ring 32)
  for (std::size_t i = 1; i < np; ++i)
    ring += (pillar.vertices[32 * np + i] - pillar.vertices[32 * np + i - 1]).cast<double>().norm();
  SectionPlane plane;
  plane.point_mm = {12.5, 0, 0};
  plane.normal = {2, 0, 0};  // normalised by the cut
  auto cut = CutSection(pillar, ErrorMapResult{}, plane);
  ASSERT_TRUE(cut.ok()) << cut.status();
  ASSERT_EQ(cut->polylines.size(), 1u);
  const auto& line = cut->polylines[0];
  // Between two rings the plane crosses a quad's long edge and diagonal:
  // 2 segments per profile step, collinear on the profile shifted in z.
  EXPECT_EQ(cut->segments, 2 * (np - 1));
  EXPECT_EQ(line.size(), 2 * (np - 1) + 1);
  EXPECT_NEAR(Length(line), ring, 1e-4) << "float vertices: the rings are shifted copies to ~1e-5";
  for (const Eigen::Vector3d& p : line) EXPECT_NEAR(p.x(), 12.5, 1e-12);
  // Counted directly: triangles with corners strictly on both sides.
  std::size_t crossed = 0;
  for (const auto& t : pillar.triangles) {
    int above = 0;
    for (int k = 0; k < 3; ++k) above += pillar.vertices[t[k]].x() >= 12.5f;
    crossed += above == 1 || above == 2;
  }
  EXPECT_EQ(cut->segments, crossed);
  EXPECT_TRUE(cut->points.empty()) << "no error map, no points";
  EXPECT_TRUE(std::isnan(cut->mean_mm));
}

TEST(Section, ASphereCutThroughItsCentreIsOneClosedLoop) {
  const TriangleMesh sphere = testing::Icosphere(20, 3);
  SectionPlane plane;
  plane.point_mm = {0, 0, 0.3};
  plane.normal = {0.2, 0.1, 1};
  auto cut = CutSection(sphere, ErrorMapResult{}, plane);
  ASSERT_TRUE(cut.ok());
  ASSERT_EQ(cut->polylines.size(), 1u);
  const auto& loop = cut->polylines[0];
  EXPECT_EQ((loop.front() - loop.back()).norm(), 0.0) << "closed";
  EXPECT_EQ(loop.size(), cut->segments + 1);
  const double r = std::sqrt(20.0 * 20 - std::pow(0.3 / plane.normal.norm(), 2));
  EXPECT_NEAR(Length(loop), 2 * M_PI * r, 0.01 * 2 * M_PI * r) << "an inscribed polygon";
}

// Points on random triangles of the pillar with random deviations: the
// section's points and statistics against a brute-force selection, whole
// and limited to a set of triangles.
TEST(Section, PointsAndValuesEqualABruteForceSelection) {
  const TriangleMesh pillar = MakePillarMesh(300);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> dev(-0.3, 0.3);
  ErrorMapResult em;
  for (int k = 0; k < 200000; ++k) {
    const auto [t, p] = RandomSurfacePoint(pillar, rng);
    em.closest_point.push_back(p);
    em.triangle_id.push_back(k % 50 == 0 ? UINT32_MAX : t);  // some unmatched
    em.deviation_mm.push_back(k % 50 == 0 ? NAN : static_cast<float>(dev(rng)));
  }
  SectionPlane plane;
  plane.point_mm = {-40, 3, 20};
  plane.normal = Eigen::Vector3d(1, 0.3, 0).normalized();
  plane.width_mm = 0.8;
  std::vector<uint8_t> ridge(pillar.num_triangles(), 0);
  for (std::size_t t = 0; t < ridge.size(); ++t)
    ridge[t] = pillar.vertices[pillar.triangles[t][0]].z() > 40;
  auto grouped = PointsByTriangle(em, pillar.num_triangles());
  ASSERT_TRUE(grouped.ok()) << grouped.status();
  for (int run = 0; run < 4; ++run) {  // with and without the ridge mask, by a pass or grouped
    const std::vector<uint8_t>* mask = run % 2 ? nullptr : &ridge;
    auto cut = CutSection(pillar, em, plane, mask ? *mask : std::vector<uint8_t>{}, 100,
                          run < 2 ? nullptr : &*grouped);
    ASSERT_TRUE(cut.ok()) << cut.status();
    std::vector<uint32_t> expect;
    double sum = 0, lo = INFINITY, hi = -INFINITY;
    for (std::size_t i = 0; i < em.triangle_id.size(); ++i) {
      if (em.triangle_id[i] == UINT32_MAX || (mask && !(*mask)[em.triangle_id[i]])) continue;
      if (std::abs((em.closest_point[i].cast<double>() - plane.point_mm).dot(plane.normal)) > 0.4)
        continue;
      expect.push_back(static_cast<uint32_t>(i));
      sum += em.deviation_mm[i];
      lo = std::min<double>(lo, em.deviation_mm[i]);
      hi = std::max<double>(hi, em.deviation_mm[i]);
    }
    ASSERT_GT(expect.size(), 100u);
    EXPECT_EQ(cut->points, expect);
    EXPECT_EQ(cut->min_mm, lo);
    EXPECT_EQ(cut->max_mm, hi);
    EXPECT_NEAR(cut->mean_mm, sum / static_cast<double>(expect.size()), 1e-12);
    EXPECT_LE(cut->whiskers.size(), 100u);
    EXPECT_GE(cut->whiskers.size(), 50u);
    for (const SectionWhisker& w : cut->whiskers) {
      EXPECT_NEAR(w.direction.norm(), 1.0, 1e-9);
      EXPECT_NEAR(w.direction.dot(plane.normal), 0.0, 1e-9) << "in the plane";
    }
  }
}

// SectionCoverage against a dense brute-force sampling of the curve, on
// the random points of the test above with a band of y removed.
TEST(Section, CoverageEqualsABruteForceSamplingOfTheCurve) {
  const TriangleMesh pillar = MakePillarMesh(300);
  std::mt19937_64 rng(4);
  ErrorMapResult em;
  for (int k = 0; k < 300000; ++k) {
    const auto [t, p] = RandomSurfacePoint(pillar, rng);
    if (p.y() > -10 && p.y() < 25) continue;  // not seen
    em.closest_point.push_back(p);
    em.triangle_id.push_back(t);
    em.deviation_mm.push_back(0.f);
  }
  SectionPlane plane;
  plane.point_mm = {-40, 3, 20};
  plane.normal = Eigen::Vector3d(1, 0.3, 0).normalized();
  plane.width_mm = 0.8;
  auto cut = CutSection(pillar, em, plane);
  ASSERT_TRUE(cut.ok()) << cut.status();
  const double d = 1.0;
  double length = 0, seen = 0;
  for (const auto& line : cut->polylines)
    for (std::size_t k = 0; k + 1 < line.size(); ++k) {
      const double l = (line[k + 1] - line[k]).norm();
      const int n = static_cast<int>(std::ceil(l / 0.005));
      for (int j = 0; j < n; ++j) {
        const Eigen::Vector3d q = line[k] + (j + 0.5) / n * (line[k + 1] - line[k]);
        length += l / n;
        for (uint32_t i : cut->points)
          if ((em.closest_point[i].cast<double>() - q).norm() <= d) {
            seen += l / n;
            break;
          }
      }
    }
  const double got = SectionCoverage(*cut, em, d);
  std::cout << "section coverage " << got << " (brute force " << seen / length << ")\n";
  EXPECT_NEAR(got, seen / length, 0.01);
  EXPECT_LT(got, 0.9) << "the band y in (-10, 25) was removed";
  EXPECT_GT(got, 0.3);
  EXPECT_EQ(SectionCoverage(SectionCut{}, em, d), 0.0) << "no curve";
}

TEST(Section, RefusesABadPlane) {
  const TriangleMesh pillar = MakePillarMesh(300);
  SectionPlane plane;
  plane.normal = Eigen::Vector3d::Zero();
  EXPECT_EQ(CutSection(pillar, {}, plane).status().code(), absl::StatusCode::kInvalidArgument);
  plane.normal = Eigen::Vector3d::UnitX();
  plane.width_mm = -1;
  EXPECT_FALSE(CutSection(pillar, {}, plane).ok());
  plane.width_mm = 1;
  EXPECT_FALSE(CutSection(pillar, {}, plane, std::vector<uint8_t>(3, 1)).ok());
  // A plane that misses the part is no error here: the plan refuses it.
  plane.point_mm = {1000, 0, 0};
  auto cut = CutSection(pillar, {}, plane);
  ASSERT_TRUE(cut.ok());
  EXPECT_TRUE(cut->polylines.empty());
}

}  // namespace
}  // namespace surfinspect
