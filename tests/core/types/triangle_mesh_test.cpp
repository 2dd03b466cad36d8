#include "core/types/triangle_mesh.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "tests/support/test_meshes.h"

namespace surfinspect {
namespace {

using Eigen::Vector3d;
using Eigen::Vector3f;

TriangleMesh OneTriangle(const Vector3f& a, const Vector3f& b, const Vector3f& c) {
  TriangleMesh m;
  m.vertices = {a, b, c};
  m.triangles = {{0, 1, 2}};
  return m;
}

// A regular tetrahedron with outward CCW faces.
TriangleMesh Tetrahedron() {
  TriangleMesh m;
  m.vertices = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  m.triangles = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
  return m;
}

TEST(TriangleMesh, FaceNormalsAreTheNormalisedCrossProducts) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> u(-50, 50);
  TriangleMesh m;
  for (int t = 0; t < 200; ++t) {
    const uint32_t base = static_cast<uint32_t>(m.vertices.size());
    for (int k = 0; k < 3; ++k) m.vertices.emplace_back(u(rng), u(rng), u(rng));
    m.triangles.push_back({base, base + 1, base + 2});
  }
  const auto normals = m.FaceNormals();
  ASSERT_EQ(normals.size(), m.num_triangles());
  for (std::size_t t = 0; t < normals.size(); ++t) {
    const Vector3d a = m.vertices[m.triangles[t][0]].cast<double>();
    const Vector3d b = m.vertices[m.triangles[t][1]].cast<double>();
    const Vector3d c = m.vertices[m.triangles[t][2]].cast<double>();
    const Vector3d n = (b - a).cross(c - a);
    EXPECT_LT((normals[t].cast<double>() - n.normalized()).norm(), 1e-6) << t;
    EXPECT_NEAR(normals[t].norm(), 1, 1e-6);
    // Perpendicular to every edge.
    EXPECT_NEAR(normals[t].cast<double>().dot((b - a).normalized()), 0, 1e-5);
    EXPECT_NEAR(normals[t].cast<double>().dot((c - b).normalized()), 0, 1e-5);
  }
}

TEST(TriangleMesh, CounterClockwiseWindingPointsTheNormalOutward) {
  EXPECT_EQ(OneTriangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0}).FaceNormals()[0], Vector3f(0, 0, 1));
  EXPECT_EQ(OneTriangle({0, 0, 0}, {0, 1, 0}, {1, 0, 0}).FaceNormals()[0], Vector3f(0, 0, -1));
  // On a closed, outward mesh every normal points away from the centroid.
  const TriangleMesh tet = Tetrahedron();
  const auto normals = tet.FaceNormals();
  for (std::size_t t = 0; t < normals.size(); ++t) {
    Vector3f centre = Vector3f::Zero();
    for (uint32_t v : tet.triangles[t]) centre += tet.vertices[v] / 3;
    EXPECT_GT(normals[t].dot(centre), 0) << t;
  }
}

TEST(TriangleMesh, DegeneracyIsRelativeToTheLongestEdge) {
  // Collinear and repeated-vertex triangles: degenerate, zero normal.
  for (const TriangleMesh& m :
       {OneTriangle({0, 0, 0}, {1, 0, 0}, {2, 0, 0}), OneTriangle({3, 3, 3}, {3, 3, 3}, {4, 5, 6}),
        OneTriangle({1, 1, 1}, {1, 1, 1}, {1, 1, 1})}) {
    EXPECT_TRUE(m.IsDegenerate(0));
    EXPECT_EQ(m.FaceNormals()[0], Vector3f::Zero());
  }
  // A sliver of height h on a unit base has twice-area h: degenerate below
  // 1e-12 * (longest edge)^2 = 1e-12.
  EXPECT_TRUE(OneTriangle({0, 0, 0}, {1, 0, 0}, {0.5f, 1e-13f, 0}).IsDegenerate(0));
  EXPECT_FALSE(OneTriangle({0, 0, 0}, {1, 0, 0}, {0.5f, 1e-9f, 0}).IsDegenerate(0));
  // A tiny but well-shaped triangle is not degenerate: the test is scale free.
  EXPECT_FALSE(OneTriangle({0, 0, 0}, {1e-5f, 0, 0}, {0, 1e-5f, 0}).IsDegenerate(0));
}

TEST(TriangleMesh, CountDegenerateCountsEachBadTriangle) {
  TriangleMesh m = Tetrahedron();
  EXPECT_EQ(m.CountDegenerate(), 0u);
  m.vertices.push_back({2, 0, 0});  // 4: collinear with vertices 5 and 6
  m.vertices.push_back({3, 0, 0});
  m.vertices.push_back({4, 0, 0});
  m.triangles.push_back({4, 5, 6});
  m.triangles.push_back({0, 0, 1});
  EXPECT_EQ(m.CountDegenerate(), 2u);
  EXPECT_TRUE(m.Validate().ok()) << "some good triangles remain";
}

TEST(TriangleMesh, ValidateNamesTheProblem) {
  auto expect_error = [](const TriangleMesh& m, const std::string& needle) {
    const absl::Status st = m.Validate();
    EXPECT_EQ(st.code(), absl::StatusCode::kInvalidArgument) << needle;
    EXPECT_NE(st.message().find(needle), std::string::npos) << st;
  };
  EXPECT_TRUE(Tetrahedron().Validate().ok());
  TriangleMesh none = Tetrahedron();
  none.triangles.clear();
  expect_error(none, "no triangles");
  TriangleMesh out_of_range = Tetrahedron();
  out_of_range.triangles[2][1] = 4;
  expect_error(out_of_range, "triangle 2 refers to vertex 4");
  for (float bad : {NAN, INFINITY}) {
    TriangleMesh nonfinite = Tetrahedron();
    nonfinite.vertices[3].y() = bad;
    expect_error(nonfinite, "vertex 3 is not finite");
  }
  expect_error(OneTriangle({0, 0, 0}, {1, 0, 0}, {2, 0, 0}), "all 1 triangles are degenerate");
}

TEST(TriangleMesh, TopologyCountsEdgesByUse) {
  // One triangle: three boundary edges.
  MeshTopology one = AnalyzeTopology(OneTriangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0}));
  EXPECT_EQ(one.boundary_edges, 3u);
  EXPECT_EQ(one.nonmanifold_edges, 0u);
  EXPECT_FALSE(one.closed());

  // A quad of two triangles: the shared diagonal is interior, 4 boundary.
  TriangleMesh quad;
  quad.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  quad.triangles = {{0, 1, 2}, {0, 2, 3}};
  EXPECT_EQ(AnalyzeTopology(quad).boundary_edges, 4u);
  EXPECT_EQ(AnalyzeTopology(quad).nonmanifold_edges, 0u);

  // A fin: a third triangle on the diagonal makes it non-manifold.
  TriangleMesh fin = quad;
  fin.vertices.push_back({0.5f, 0.5f, 1});
  fin.triangles.push_back({0, 2, 4});
  const MeshTopology f = AnalyzeTopology(fin);
  EXPECT_EQ(f.nonmanifold_edges, 1u);
  EXPECT_EQ(f.boundary_edges, 6u);  // 4 of the quad + 2 of the fin

  // Closed: the tetrahedron and a box. Removing a face opens 3 edges.
  EXPECT_TRUE(AnalyzeTopology(Tetrahedron()).closed());
  const TriangleMesh box = testing::Box(Vector3d::Zero(), Vector3d(1, 2, 3));
  EXPECT_TRUE(AnalyzeTopology(box).closed());
  TriangleMesh open = Tetrahedron();
  open.triangles.pop_back();
  EXPECT_EQ(AnalyzeTopology(open).boundary_edges, 3u);
  EXPECT_FALSE(AnalyzeTopology(open).closed());

  // The edge (a, b) is the edge (b, a): opposite windings still pair up.
  TriangleMesh flipped = quad;
  flipped.triangles[1] = {0, 3, 2};
  EXPECT_EQ(AnalyzeTopology(flipped).boundary_edges, 4u);
}

TEST(TriangleMesh, TopologyOfAClosedSphere) {
  // A closed triangulated sphere: every edge used twice (3F = 2E) and
  // V - E + F = 2; one face fewer opens exactly its three edges.
  TriangleMesh sphere = testing::Icosphere(10, 2);
  EXPECT_TRUE(AnalyzeTopology(sphere).closed());
  const std::size_t f = sphere.num_triangles();
  EXPECT_EQ(sphere.vertices.size() + f - 3 * f / 2, 2u);
  sphere.triangles.erase(sphere.triangles.begin() + 17);
  EXPECT_EQ(AnalyzeTopology(sphere).boundary_edges, 3u);
}

TEST(TriangleMesh, BoundsSpanTheVertices) {
  const TriangleMesh box = testing::Box(Vector3d(-1, 2, -3), Vector3d(4, 5, 6));
  const Bounds3 b = ComputeBounds(box);
  EXPECT_EQ(b.min, Vector3d(-1, 2, -3));
  EXPECT_EQ(b.max, Vector3d(4, 5, 6));
  EXPECT_TRUE(ComputeBounds(TriangleMesh{}).empty());
}

}  // namespace
}  // namespace surfinspect
