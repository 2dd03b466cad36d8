// Expected meshes are what Assimp 5.2.5 (Triangulate + JoinIdenticalVertices,
// the flags io_mesh.cpp used) produced for the same PLY text.
#include "core/io/polygon_mesh.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/io/ply_mesh.h"

namespace surfinspect {
namespace {

std::string Ply(const std::string& vertices, int nv, const std::string& faces, int nf) {
  return "ply\nformat ascii 1.0\nelement vertex " + std::to_string(nv) +
         "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
         std::to_string(nf) + "\nproperty list uchar int vertex_indices\nend_header\n" + vertices +
         faces;
}

void ExpectMesh(const TriangleMesh& m, const std::vector<Eigen::Vector3f>& v,
                const std::vector<Triangle>& t) {
  ASSERT_EQ(m.vertices.size(), v.size());
  for (std::size_t i = 0; i < v.size(); ++i) EXPECT_EQ(m.vertices[i], v[i]) << "vertex " << i;
  ASSERT_EQ(m.triangles.size(), t.size());
  for (std::size_t i = 0; i < t.size(); ++i) EXPECT_EQ(m.triangles[i], t[i]) << "triangle " << i;
}

TEST(TriangulateAndMerge, DropsUnreferencedMergesEqualAndKeepsFileOrder) {
  auto m = ParsePlyMesh(Ply("5 5 5\n1 0 0\n0 1 0\n0 0 0\n1 0 0\n1.0000001 1 0\n", 6,
                            "3 3 1 2\n3 4 5 2\n4 3 4 5 2\n", 3));
  ASSERT_TRUE(m.ok()) << m.status();
  ExpectMesh(*m, {{1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {std::nextafter(1.f, 2.f), 1, 0}},
             {{2, 0, 1}, {0, 3, 1}, {2, 0, 3}, {2, 3, 1}});
}

TEST(TriangulateAndMerge, MergesOnlyEqualCoordinatesWithMinusZeroEqualToZero) {
  auto m =
      ParsePlyMesh(Ply("5 5 5\n1 0 0\n1.000001 0 0\n0 1 0\n0 0 0\n5 5 5\n1.00001 0 0\n-0 1 0\n", 8,
                       "3 5 1 3\n3 2 6 4\n3 7 1 4\n", 3));
  ASSERT_TRUE(m.ok()) << m.status();
  ExpectMesh(*m, {{1, 0, 0}, {1.000001f, 0, 0}, {0, 1, 0}, {0, 0, 0}, {5, 5, 5}, {1.00001f, 0, 0}},
             {{4, 0, 2}, {1, 5, 3}, {2, 0, 3}});
}

TEST(TriangulateAndMerge, FansAConcaveQuadFromItsConcaveCorner) {
  auto m = ParsePlyMesh(Ply("0 0 0\n1 0 0\n0.2 0.2 0\n0 1 0\n", 4, "4 0 1 2 3\n", 1));
  ASSERT_TRUE(m.ok()) << m.status();
  ExpectMesh(*m, {{0, 0, 0}, {1, 0, 0}, {0.2f, 0.2f, 0}, {0, 1, 0}}, {{2, 3, 0}, {2, 0, 1}});
}

TEST(TriangulateAndMerge, RotatesFacesThatStartWhereThePreviousStartedInMeshesWithQuads) {
  auto m = ParsePlyMesh(Ply("0 0 0\n1 0 0\n1 1 0\n0 1 0\n-1 1 0\n-1 0 0\n", 6,
                            "4 0 1 2 3\n3 0 3 4\n3 0 4 5\n4 0 5 4 3\n", 4));
  ASSERT_TRUE(m.ok()) << m.status();
  ExpectMesh(*m, {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {-1, 1, 0}, {-1, 0, 0}},
             {{0, 1, 2}, {0, 2, 3}, {4, 0, 3}, {0, 4, 5}, {4, 0, 5}, {4, 3, 0}});
  // Without quads nothing is rotated.
  auto t = ParsePlyMesh(Ply("0 0 0\n1 0 0\n1 1 0\n0 1 0\n", 4, "3 0 1 2\n3 0 2 3\n", 2));
  ASSERT_TRUE(t.ok()) << t.status();
  ExpectMesh(*t, {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{0, 1, 2}, {0, 2, 3}});
}

TEST(TriangulateAndMerge, RefusesBadInputDirectly) {
  IndexedPolygons p;
  p.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  p.corners = {0, 1, 5};
  p.sizes = {3};
  EXPECT_FALSE(TriangulateAndMerge(p, "m").ok());
  p.corners = {0, 1, 2, 0, 1};
  p.sizes = {5};
  EXPECT_FALSE(TriangulateAndMerge(p, "m").ok());
}

TEST(ParseMeshCoordinate, MatchesAssimpsParserAndRefusesNonNumbers) {
  float f = 0;
  ASSERT_TRUE(ParseMeshCoordinate("1.000001", &f));
  EXPECT_EQ(f, 1.000001f);
  ASSERT_TRUE(ParseMeshCoordinate("-2.5e2", &f));
  EXPECT_EQ(f, -250.f);
  ASSERT_TRUE(ParseMeshCoordinate("nan", &f));
  EXPECT_TRUE(std::isnan(f));
  for (const char* bad : {"", "1,5", "x", "1.5.5", "--1", "1e", "0x10"})
    EXPECT_FALSE(ParseMeshCoordinate(bad, &f)) << bad;
  double d = 0;
  ASSERT_TRUE(ParseMeshCoordinate("0.125", &d));
  EXPECT_EQ(d, 0.125);
}

}  // namespace
}  // namespace surfinspect
