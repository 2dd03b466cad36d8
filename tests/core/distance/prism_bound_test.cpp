#include "core/distance/prism_bound.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "core/distance/point_triangle.h"

namespace surfinspect {
namespace {

using Eigen::Vector3d;

Vector3d Normal(const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  const Vector3d n = (b - a).cross(c - a);
  return n.norm() > 0 ? Vector3d(n.normalized()) : Vector3d::Zero();
}

// Never above the exact kernel's squared distance: on random triangles,
// slivers down to 2A/L^2 = 1e-9 included, and points near, on and far.
TEST(PrismBound, IsALowerBoundOfTheKernelsDistance) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  int tight = 0, total = 0;
  for (int i = 0; i < 4000; ++i) {
    const Vector3d a(u(rng), u(rng), u(rng)), d = Vector3d(u(rng), u(rng), u(rng)).normalized();
    const Vector3d e = d.cross(Vector3d(u(rng), u(rng), u(rng))).normalized();
    const double h = i % 2 ? std::abs(u(rng)) : std::pow(10.0, -(i % 10));
    // Float vertices, as the mesh stores them.
    const Vector3d b = (a + 30 * d).cast<float>().cast<double>();
    const Vector3d c = (a + 30 * u(rng) * d + 30 * h * e).cast<float>().cast<double>();
    const Vector3d fa = a.cast<float>().cast<double>();
    const Vector3d n = Normal(fa, b, c);
    const PrismBound bound = MakePrismBound(fa, b, c, n);
    for (int k = 0; k < 20; ++k) {
      const double scale = std::pow(10.0, static_cast<int>(k % 5) - 3);
      const Vector3d p = k == 0   ? fa
                         : k == 1 ? Vector3d(0.5 * (fa + b))
                                  : Vector3d(fa + 30 * Vector3d(u(rng), u(rng), u(rng)) +
                                             scale * Vector3d(u(rng), u(rng), u(rng)));
      const double exact = ClosestPointOnTriangle(p, fa, b, c).squared_distance;
      const double plane2 = PlaneBound2(bound, n, p - fa);
      const double prism2 = PrismBound2(bound, plane2, p - fa, p - b, p - c);
      ASSERT_LE(plane2, prism2);
      ASSERT_LE(prism2, exact) << "triangle " << i << " point " << k << " h " << h;
      ++total;
      tight += prism2 >= 0.5 * exact;
    }
  }
  // And it is worth computing: most points get at least half the distance.
  EXPECT_GT(tight, total / 2) << tight << " of " << total;
}

TEST(PrismBound, OutsideAnEdgeTheBoundIsTheEdgeDistance) {
  const Vector3d a(0, 0, 0), b(10, 0, 0), c(0, 10, 0), n(0, 0, 1);
  const PrismBound bound = MakePrismBound(a, b, c, n);
  EXPECT_NEAR(bound.edge[0].y(), -1, 1e-15);  // AB's outward normal points away from c
  const Vector3d p(5, -3, 4);                 // 3 outside AB, 4 above the plane
  const double plane2 = PlaneBound2(bound, n, p - a);
  EXPECT_NEAR(plane2, 16, 1e-9);
  EXPECT_NEAR(PrismBound2(bound, plane2, p - a, p - b, p - c), 25, 1e-9);
  EXPECT_DOUBLE_EQ(ClosestPointOnTriangle(p, a, b, c).squared_distance, 25);
}

TEST(PrismBound, ADegenerateTriangleBoundsNothing) {
  const Vector3d a(0, 0, 0), b(1, 0, 0), c(2, 0, 0);
  const PrismBound bound = MakePrismBound(a, b, c, Vector3d::Zero());
  const Vector3d p(0, 5, 5);
  EXPECT_EQ(PrismBound2(bound, PlaneBound2(bound, Vector3d::Zero(), p - a), p - a, p - b, p - c),
            0.0);
}

}  // namespace
}  // namespace surfinspect
