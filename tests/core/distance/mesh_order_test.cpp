// Covers core/distance/mesh_order.cpp: the order is a renumbering (every
// triangle and vertex once, corners kept), it puts near triangles near in
// memory, it does not depend on the thread count, and a mesh index built on
// it still answers in the mesh's ids, ties to the lower id.
#include "core/distance/mesh_order.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <numeric>
#include <random>

#include "core/distance/mesh_index.h"
#include "tests/support/test_meshes.h"

namespace surfinspect {
namespace {

// The torus with its triangles shuffled (a tessellator's arbitrary order)
// and one vertex no triangle uses.
TriangleMesh ShuffledTorus(uint64_t seed) {
  TriangleMesh m = testing::Torus(40, 10, 60, 20);
  std::shuffle(m.triangles.begin(), m.triangles.end(), std::mt19937_64(seed));
  m.vertices.emplace_back(500, 500, 500);
  return m;
}

Eigen::Vector3f Centroid(const TriangleMesh& m, uint32_t t) {
  const Triangle& tri = m.triangles[t];
  return (m.vertices[tri[0]] + m.vertices[tri[1]] + m.vertices[tri[2]]) / 3;
}

// Mean distance between the centroids of consecutive triangles.
double MeanStep(const TriangleMesh& m) {
  double sum = 0;
  for (uint32_t t = 1; t < m.num_triangles(); ++t)
    sum += (Centroid(m, t) - Centroid(m, t - 1)).norm();
  return sum / static_cast<double>(m.num_triangles() - 1);
}

TEST(MeshOrder, IsARenumberingThatKeepsEveryTriangleAndItsCorners) {
  const TriangleMesh m = ShuffledTorus(1);
  const MeshOrder order = OrderMesh(m);
  ASSERT_EQ(order.mesh_triangle.size(), m.num_triangles());
  ASSERT_EQ(order.ordered.num_triangles(), m.num_triangles());
  ASSERT_EQ(order.ordered.vertices.size(), m.vertices.size());
  std::vector<uint32_t> sorted = order.mesh_triangle;
  std::sort(sorted.begin(), sorted.end());
  std::vector<uint32_t> all(m.num_triangles());
  std::iota(all.begin(), all.end(), 0u);
  EXPECT_EQ(sorted, all);
  std::vector<uint32_t> vertices = order.position_of_vertex;
  std::sort(vertices.begin(), vertices.end());
  std::vector<uint32_t> every_vertex(m.vertices.size());
  std::iota(every_vertex.begin(), every_vertex.end(), 0u);
  EXPECT_EQ(vertices, every_vertex);
  for (uint32_t v = 0; v < m.vertices.size(); ++v)
    EXPECT_EQ(order.ordered.vertices[order.position_of_vertex[v]], m.vertices[v]);
  for (uint32_t i = 0; i < m.num_triangles(); ++i) {
    const uint32_t t = order.mesh_triangle[i];
    EXPECT_EQ(order.position_of_triangle[t], i);
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(order.ordered.triangles[i][k], order.position_of_vertex[m.triangles[t][k]]);
  }
  // The unused vertex comes last.
  EXPECT_EQ(order.position_of_vertex.back(), m.vertices.size() - 1);
  EXPECT_TRUE(order.ordered.Validate().ok());
}

TEST(MeshOrder, KeepOrderIsTheIdentity) {
  const TriangleMesh m = ShuffledTorus(5);
  const MeshOrder order = KeepOrder(m);
  for (uint32_t t = 0; t < m.num_triangles(); ++t) {
    EXPECT_EQ(order.mesh_triangle[t], t);
    EXPECT_EQ(order.position_of_triangle[t], t);
    EXPECT_EQ(order.ordered.triangles[t], m.triangles[t]);
  }
  for (uint32_t v = 0; v < m.vertices.size(); ++v) EXPECT_EQ(order.position_of_vertex[v], v);
  EXPECT_EQ(order.ordered.vertices, m.vertices);
  EXPECT_TRUE(order.identity);
  EXPECT_FALSE(OrderMesh(m).identity);
}

TEST(MeshOrder, PutsNearTrianglesNearInMemory) {
  const TriangleMesh m = ShuffledTorus(2);
  const double shuffled = MeanStep(m);
  const double ordered = MeanStep(OrderMesh(m).ordered);
  // A triangle here is ~4 mm across; the shuffled steps average ~60 mm.
  EXPECT_LT(ordered, shuffled / 8) << ordered << " vs " << shuffled;
}

TEST(MeshOrder, DoesNotDependOnTheThreadCount) {
  const TriangleMesh m = ShuffledTorus(3);
  MeshOrder one, two;
  tbb::task_arena(1).execute([&] { one = OrderMesh(m); });
  tbb::task_arena(2).execute([&] { two = OrderMesh(m); });
  EXPECT_EQ(one.mesh_triangle, two.mesh_triangle);
  EXPECT_EQ(one.position_of_vertex, two.position_of_vertex);
}

// On a vertex every triangle around it is at distance 0, exactly: the
// answer must be the lowest mesh id among them wherever the order put them.
// The same mesh in two triangle orders gives the same answers, mapped by id.
TEST(MeshOrder, AnIndexAnswersInMeshIdsAndTiesGoToTheLowerId) {
  const TriangleMesh m = ShuffledTorus(4);
  auto index = MeshIndex::Build(m);
  ASSERT_TRUE(index.ok()) << index.status();
  std::vector<uint32_t> lowest(m.vertices.size(), UINT32_MAX);
  for (uint32_t t = 0; t < m.num_triangles(); ++t)
    for (uint32_t v : m.triangles[t]) lowest[v] = std::min(lowest[v], t);
  int ties = 0;
  for (uint32_t v = 0; v < m.vertices.size(); ++v) {
    if (lowest[v] == UINT32_MAX) continue;
    const ClosestPoint got = (*index)->Closest(m.vertices[v].cast<double>());
    ASSERT_TRUE(got.matched());
    EXPECT_EQ(got.distance_mm, 0);
    EXPECT_EQ(got.triangle_id, lowest[v]) << "vertex " << v;
    ++ties;
  }
  EXPECT_GT(ties, 1000);

  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-55, 55);
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < 400; ++i) pts.emplace_back(u(rng), u(rng), u(rng) / 4);
  TriangleMesh shuffled = testing::Torus(40, 10, 30, 12);
  std::vector<uint32_t> perm(shuffled.num_triangles());
  std::iota(perm.begin(), perm.end(), 0u);
  std::shuffle(perm.begin(), perm.end(), rng);
  TriangleMesh original = shuffled;
  for (uint32_t i = 0; i < perm.size(); ++i) shuffled.triangles[i] = original.triangles[perm[i]];
  auto a = MeshIndex::Build(original), b = MeshIndex::Build(shuffled);
  ASSERT_TRUE(a.ok() && b.ok());
  for (const Eigen::Vector3d& p : pts) {
    const ClosestPoint x = (*a)->Closest(p), y = (*b)->Closest(p);
    ASSERT_TRUE(x.matched() && y.matched());
    // Off the edges and corners the closest triangle is unique (on them a
    // tie may go to another triangle in the other numbering).
    if (x.feature != ClosestFeature::kFace) continue;
    EXPECT_EQ(x.triangle_id, perm[y.triangle_id]);
    EXPECT_EQ(x.distance_mm, y.distance_mm);
    EXPECT_EQ(x.point, y.point);
  }
}

}  // namespace
}  // namespace surfinspect
