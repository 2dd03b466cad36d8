#include "core/distance/point_triangle.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <random>

#include "tests/support/test_meshes.h"

namespace surfinspect {
namespace {

using Eigen::Vector3d;
using F = ClosestFeature;
using testing::DistanceByProjection;

// Agreement "within 1e-9 relative", with a 1e-9 mm floor so that points on
// the triangle (true distance ~1e-16) are not judged by rounding noise.
void ExpectSameDistance(double got, double want) {
  EXPECT_NEAR(got, want, 1e-9 * std::max(1.0, want));
}

bool OnTriangle(const Vector3d& q, const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  const Vector3d n = (b - a).cross(c - a);
  const double scale = std::max({(b - a).norm(), (c - a).norm(), 1.0});
  if (std::abs((q - a).dot(n.normalized())) > 1e-9 * scale) return false;
  const double tol = -1e-9 * n.squaredNorm();
  return (b - q).cross(c - q).dot(n) >= tol && (c - q).cross(a - q).dot(n) >= tol &&
         (a - q).cross(b - q).dot(n) >= tol;
}

TEST(PointTriangle, RandomTrianglesAndPointsMatchTheProjectionOracle) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-10, 10);
  auto rv = [&] { return Vector3d(u(rng), u(rng), u(rng)); };
  for (int i = 0; i < 20000; ++i) {
    const Vector3d a = rv(), b = rv(), c = rv();
    // Near, far (1e4 mm) and offset (CAD coordinates far from the origin).
    const double scale = i % 3 == 0 ? 1.0 : i % 3 == 1 ? 1e3 : 0.05;
    const Vector3d offset = i % 5 == 0 ? Vector3d(2500, -1800, 900) : Vector3d::Zero();
    const Vector3d p = rv() * scale + offset;
    const auto r = ClosestPointOnTriangle(p, a + offset, b + offset, c + offset);
    const double want = DistanceByProjection(p, a + offset, b + offset, c + offset);
    ExpectSameDistance(std::sqrt(r.squared_distance), want);
    EXPECT_NEAR((p - r.point).squaredNorm(), r.squared_distance,
                1e-12 * r.squared_distance + 1e-20);
    ASSERT_TRUE(OnTriangle(r.point - offset, a, b, c)) << i;
  }
}

// Builds points inside each Voronoi region by construction and checks that
// the reported feature is that region's.
TEST(PointTriangle, ReportsTheFeatureOfEachVoronoiRegion) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.05, 0.9), h(-3, 3), coord(-5, 5);
  int checked = 0;
  for (int i = 0; i < 3000; ++i) {
    const std::array<Vector3d, 3> v{Vector3d(coord(rng), coord(rng), coord(rng)),
                                    Vector3d(coord(rng), coord(rng), coord(rng)),
                                    Vector3d(coord(rng), coord(rng), coord(rng))};
    const Vector3d n = (v[1] - v[0]).cross(v[2] - v[0]);
    if (n.norm() < 1.0) continue;  // keep away from slivers for this test
    const Vector3d nu = n.normalized();
    // Face: a barycentric interior point plus any height.
    const double s = u(rng), t = u(rng) * (1 - s);
    const Vector3d face_p = v[0] + s * (v[1] - v[0]) + t * (v[2] - v[0]) + h(rng) * nu;
    EXPECT_EQ(ClosestPointOnTriangle(face_p, v[0], v[1], v[2]).feature, F::kFace);
    for (int k = 0; k < 3; ++k) {
      const Vector3d& e0 = v[k];
      const Vector3d& e1 = v[(k + 1) % 3];
      // Edge: an interior edge point moved outward in the plane and along n.
      const Vector3d out = (e1 - e0).cross(nu).normalized();  // CCW: points away from the face
      const Vector3d edge_p = e0 + u(rng) * (e1 - e0) + 0.5 * out + h(rng) * nu;
      const auto re = ClosestPointOnTriangle(edge_p, v[0], v[1], v[2]);
      EXPECT_EQ(re.feature, static_cast<F>(static_cast<int>(F::kEdgeAB) + k)) << i << " edge " << k;
      // Vertex: outside both incident edges' slabs, i.e. in the cone spanned
      // by the two outward edge directions at the vertex.
      const Vector3d& prev = v[(k + 2) % 3];
      const Vector3d d = (e0 - e1).normalized() + (e0 - prev).normalized();
      const Vector3d vertex_p = e0 + 0.7 * d.normalized() + h(rng) * nu;
      const auto rv = ClosestPointOnTriangle(vertex_p, v[0], v[1], v[2]);
      EXPECT_EQ(rv.feature, static_cast<F>(static_cast<int>(F::kVertexA) + k)) << i;
      EXPECT_EQ(rv.point, e0);
      ++checked;
    }
  }
  EXPECT_GT(checked, 3000);
}

TEST(PointTriangle, PointsOnVerticesAndEdgesHaveZeroDistance) {
  const Vector3d a(1, 2, 3), b(4, 2, 3.5), c(2, 6, 2);
  for (const Vector3d& p : {a, b, c})
    EXPECT_EQ(ClosestPointOnTriangle(p, a, b, c).squared_distance, 0);
  for (double t : {0.0, 0.25, 0.5, 1.0}) {
    EXPECT_NEAR(ClosestPointOnTriangle(a + t * (b - a), a, b, c).squared_distance, 0, 1e-28);
    EXPECT_NEAR(ClosestPointOnTriangle(b + t * (c - b), a, b, c).squared_distance, 0, 1e-28);
    EXPECT_NEAR(ClosestPointOnTriangle(c + t * (a - c), a, b, c).squared_distance, 0, 1e-28);
  }
  EXPECT_EQ(ClosestPointOnTriangle(a, a, b, c).feature, F::kVertexA);
  EXPECT_EQ(ClosestPointOnTriangle(c, a, b, c).feature, F::kVertexC);
}

TEST(PointTriangle, DegenerateTrianglesFallBackToSegments) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-4, 4);
  auto rv = [&] { return Vector3d(u(rng), u(rng), u(rng)); };
  for (int i = 0; i < 2000; ++i) {
    const Vector3d a = rv(), b = rv();
    const Vector3d p = rv();
    // Collinear, two coincident and all three coincident vertices.
    const std::array<std::array<Vector3d, 3>, 3> cases{
        {{a, b, a + 0.3 * (b - a)}, {a, a, b}, {a, a, a}}};
    for (const auto& t : cases) {
      const auto r = ClosestPointOnTriangle(p, t[0], t[1], t[2]);
      ASSERT_TRUE(std::isfinite(r.squared_distance));
      EXPECT_NE(r.feature, F::kFace);
      // Oracle: the segment [a, b] (or the point a).
      const double len2 = (b - a).squaredNorm();
      double want = (p - a).norm();
      if (t[2] != a || t[1] != a) {
        const double s = std::clamp((p - a).dot(b - a) / len2, 0.0, 1.0);
        want = (p - (a + s * (b - a))).norm();
      }
      ExpectSameDistance(std::sqrt(r.squared_distance), want);
    }
  }
}

TEST(PointTriangle, FeatureHelpers) {
  // Every feature: its index (an edge's first vertex, or the vertex) and kind.
  const struct {
    F f;
    int index;
    bool edge, vertex;
  } want[] = {{F::kFace, -1, false, false},  {F::kEdgeAB, 0, true, false},
              {F::kEdgeBC, 1, true, false},  {F::kEdgeCA, 2, true, false},
              {F::kVertexA, 0, false, true}, {F::kVertexB, 1, false, true},
              {F::kVertexC, 2, false, true}};
  for (const auto& w : want) {
    EXPECT_EQ(FeatureIndex(w.f), w.index) << static_cast<int>(w.f);
    EXPECT_EQ(IsEdge(w.f), w.edge) << static_cast<int>(w.f);
    EXPECT_EQ(IsVertex(w.f), w.vertex) << static_cast<int>(w.f);
  }
}

}  // namespace
}  // namespace surfinspect
