// Covers core/distance/prism_bound.cpp (the double bound) and
// core/distance/leaf_block.cpp (the lanes the float leaf bound reads, in each ISA).
#include "core/distance/prism_bound.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "core/distance/point_triangle.h"
#include "core/distance/wide_bvh.h"

namespace surfinspect {
namespace {

using Eigen::Vector3d;
using Eigen::Vector3f;

// The leaf bound, as the search computes it in float, for one triangle in
// lane 1 of a block (the other lanes unused); SSE2 and AVX2 must agree to
// the bit.
double LeafBound2(const Vector3d& a, const Vector3d& b, const Vector3d& c, const Vector3d& n,
                  const Vector3d& p) {
  wide::LeafBlock block = EmptyLeafBlock();
  FillLeafLane(block, 1, 7, a.cast<float>(), b.cast<float>(), c.cast<float>(), n,
               ClassifyTriangle(a, b, c));
  float sse2[wide::kLeafWidth], avx2[wide::kLeafWidth];
  LeafBounds2(SearchIsa::kSse2, block, p, sse2);
  LeafBounds2(SearchIsa::kAvx2, block, p, avx2);
  EXPECT_EQ(sse2[1], avx2[1]);
  return sse2[1];
}

Vector3d Normal(const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  const Vector3d n = (b - a).cross(c - a);
  return n.norm() > 0 ? Vector3d(n.normalized()) : Vector3d::Zero();
}

// Never above the exact kernel's squared distance by more than the float
// sum's 3 2^-24 of it, which the search's padded radius absorbs: on random
// triangles, slivers down to 2A/L^2 = 1e-9 included, and points near, on
// and far.
TEST(PrismBound, IsALowerBoundOfTheKernelsDistance) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  int tight = 0, total = 0;
  for (int i = 0; i < 4000; ++i) {
    const Vector3d a(u(rng), u(rng), u(rng)), d = Vector3d(u(rng), u(rng), u(rng)).normalized();
    const Vector3d e = d.cross(Vector3d(u(rng), u(rng), u(rng))).normalized();
    const double h = i % 2 ? std::abs(u(rng)) : std::pow(10.0, -(i % 10));
    // Float vertices, as the mesh stores them (each rounded in a statement
    // of its own, so no expression template can skip the rounding).
    const Vector3f af = a.cast<float>(), bf = (a + 30 * d).cast<float>(),
                   cf = (a + 30 * u(rng) * d + 30 * h * e).cast<float>();
    const Vector3d fa = af.cast<double>(), b = bf.cast<double>(), c = cf.cast<double>();
    const Vector3d n = Normal(fa, b, c);
    for (int k = 0; k < 20; ++k) {
      const double scale = std::pow(10.0, static_cast<int>(k % 5) - 3);
      const Vector3d p = k == 0   ? fa
                         : k == 1 ? Vector3d(0.5 * (fa + b))
                                  : Vector3d(fa + 30 * Vector3d(u(rng), u(rng), u(rng)) +
                                             scale * Vector3d(u(rng), u(rng), u(rng)));
      const double exact = ClosestPointOnTriangle(p, fa, b, c).squared_distance;
      const double prism2 = LeafBound2(fa, b, c, n, p);
      ASSERT_LE(prism2, exact * (1 + 0x3p-24)) << "triangle " << i << " point " << k << " h " << h;
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
  // Lowered by the slack, about 1.2e-6 |p - vertex|_1 per term, and the margin.
  EXPECT_NEAR(LeafBound2(a, b, c, n, Vector3d(5, 2, 4)), 16, 1e-3);  // above the face
  const Vector3d p(5, -3, 4);  // 3 outside AB, 4 above the plane
  EXPECT_NEAR(LeafBound2(a, b, c, n, p), 25, 1e-3);
  EXPECT_DOUBLE_EQ(ClosestPointOnTriangle(p, a, b, c).squared_distance, 25);
}

TEST(PrismBound, ADegenerateTriangleBoundsNothing) {
  const Vector3d a(0, 0, 0), b(1, 0, 0), c(2, 0, 0);
  EXPECT_EQ(LeafBound2(a, b, c, Vector3d::Zero(), Vector3d(0, 5, 5)), 0.0);
}

// Unused lanes are skipped by their triangle id, and a full block gives
// each lane its own triangle's bound.
TEST(PrismBound, EachLaneOfABlockIsItsOwnTriangle) {
  wide::LeafBlock block = EmptyLeafBlock();
  EXPECT_EQ(block.triangle[3], UINT32_MAX);
  for (int lane = 0; lane < wide::kLeafWidth; ++lane)
    FillLeafLane(block, lane, lane, Vector3f(0, 0, lane), Vector3f(1, 0, lane),
                 Vector3f(0, 1, lane), Vector3d(0, 0, 1), TriangleShape::kRegular);
  float out[wide::kLeafWidth];
  LeafBounds2(SearchIsa::kAuto, block, Vector3d(0.2, 0.2, 10), out);
  for (int lane = 0; lane < wide::kLeafWidth; ++lane)
    EXPECT_NEAR(out[lane], (10.0 - lane) * (10.0 - lane), 1e-3) << lane;
}

}  // namespace
}  // namespace surfinspect
