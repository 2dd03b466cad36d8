// One triangle's coverage sampling (core/plan/triangle_raster.cpp) against
// brute force: every sample's verdict equals a check of every point, for
// the triangle's own points alone and after a second call with points
// beyond its edges (the neighbours' bands, as coverage feeds them).
#include "core/plan/triangle_raster.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

namespace surfinspect {
namespace {

TriangleMesh OneTriangle(const Eigen::Vector3f& a, const Eigen::Vector3f& b,
                         const Eigen::Vector3f& c) {
  TriangleMesh m;
  m.vertices = {a, b, c};
  m.triangles = {{0, 1, 2}};
  return m;
}

// A tilted triangle, ~40 mm across.
TriangleMesh Tilted() { return OneTriangle({0, 0, 0}, {40, 5, 8}, {10, 35, -6}); }

// Points on the plane of `m` at barycentric (u, v) (outside the triangle
// when u, v < 0 or u + v > 1).
Eigen::Vector3f OnPlane(const TriangleMesh& m, double u, double v) {
  const Eigen::Vector3d a = m.vertices[0].cast<double>(), b = m.vertices[1].cast<double>(),
                        c = m.vertices[2].cast<double>();
  return (a + u * (b - a) + v * (c - a)).cast<float>();
}

// Feeds the points in two calls, as coverage does (own points, then the
// neighbours'), and checks every sample against brute force over all
// points fed so far.
void ExpectBruteForce(const TriangleRaster& raster, const std::vector<Eigen::Vector3f>& points,
                      double reach, std::size_t* covered) {
  std::size_t n = 0, samples = 0;
  raster.ForEachSample([&](const Eigen::Vector3d& q, bool hit) {
    bool near = false;
    for (const auto& p : points) near |= (p.cast<double>() - q).norm() <= reach;
    EXPECT_EQ(hit, near) << "sample " << q.transpose();
    n += hit;
    ++samples;
  });
  EXPECT_EQ(samples, raster.samples());
  EXPECT_EQ(n, raster.CountCovered());
  *covered = n;
}

TEST(TriangleFrame, ProjectsIntoThePlaneAndBack) {
  const TriangleMesh m = Tilted();
  const TriangleFrame f(m, 0);
  ASSERT_TRUE(f.ok);
  EXPECT_NEAR(f.area,
              0.5 * (m.vertices[1] - m.vertices[0])
                        .cast<double>()
                        .cross((m.vertices[2] - m.vertices[0]).cast<double>())
                        .norm(),
              1e-9);
  for (int k = 0; k < 3; ++k) {
    EXPECT_LT((f.Project(m.vertices[k]) - f.corner[k]).norm(), 1e-4);
    EXPECT_LT((f.At(f.corner[k]) - m.vertices[k].cast<double>()).norm(), 1e-9);
  }
  const Eigen::Vector2d centroid = (f.corner[0] + f.corner[1] + f.corner[2]) / 3;
  for (int k = 0; k < 3; ++k) EXPECT_LT(f.Outside(centroid, k), 0);
  EXPECT_GT(f.Outside(f.Project(OnPlane(m, -0.2, 0.5)), 2), 0);  // beyond edge 2 (c to a)
}

TEST(TriangleRaster, OwnPointsThenNeighboursMatchBruteForce) {
  const TriangleMesh m = Tilted();
  const double reach = 0.8;
  TriangleRaster raster(m, 0, 0.4, reach);
  ASSERT_TRUE(raster.ok());
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-0.1, 1.1);
  std::vector<Eigen::Vector3f> own, beyond;
  for (int k = 0; k < 4000; ++k) {
    const double a = u(rng), b = u(rng);
    if (std::hypot(a - 0.3, b - 0.3) < 0.12) continue;  // an unseen disc inside
    (a >= 0 && b >= 0 && a + b <= 1 ? own : beyond).push_back(OnPlane(m, a, b));
  }
  raster.Cover([&](auto&& add) {
    for (const auto& q : own) add(q, true);
  });
  std::size_t by_own = 0, by_all = 0;
  ExpectBruteForce(raster, own, reach, &by_own);
  EXPECT_LT(by_own, raster.samples());  // the disc and the edges' slivers are left
  std::vector<Eigen::Vector3f> all = own;
  all.insert(all.end(), beyond.begin(), beyond.end());
  raster.Cover([&](auto&& add) {
    for (const auto& q : beyond) add(q, false);
  });
  ExpectBruteForce(raster, all, reach, &by_all);
  EXPECT_GT(by_all, by_own);            // the points beyond the edges reach in
  EXPECT_LT(by_all, raster.samples());  // the disc stays unseen
  EXPECT_FALSE(raster.AllCovered());
}

TEST(TriangleRaster, PointsFarOffThePlaneOrBeyondReachCoverNothing) {
  const TriangleMesh m = Tilted();
  TriangleRaster raster(m, 0, 0.5, 0.6);
  raster.Cover([&](auto&& add) {
    add(OnPlane(m, -0.5, 0.5), false);  // ~15 mm beyond an edge
    add(Eigen::Vector3f(500, 500, 500), false);
  });
  EXPECT_EQ(raster.CountCovered(), 0u);
}

TEST(TriangleRaster, DegenerateTriangleIsOneSampleNeverCovered) {
  const TriangleMesh m = OneTriangle({0, 0, 0}, {1, 1, 1}, {2, 2, 2});
  TriangleRaster raster(m, 0, 0.5, 1.0);
  EXPECT_FALSE(raster.ok());
  raster.Cover([&](auto&& add) { add(Eigen::Vector3f(1, 1, 1), true); });
  EXPECT_EQ(raster.samples(), 1u);
  EXPECT_EQ(raster.CountCovered(), 0u);
}

}  // namespace
}  // namespace surfinspect
