#include "core/io/io_mesh.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "tests/support/temp_dir.h"

namespace surfinspect {
namespace {

using testing::TempDir;
using testing::WriteBytes;

// Unit cube [0,10]^3 with outward CCW triangles.
TriangleMesh Cube() {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back(10.f * (i & 1), 10.f * ((i >> 1) & 1), 10.f * ((i >> 2) & 1));
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

// Signed volume by the divergence theorem: positive when normals face out.
double SignedVolume(const TriangleMesh& m) {
  double v = 0;
  for (const auto& t : m.triangles)
    v += m.vertices[t[0]].cast<double>().dot(
             m.vertices[t[1]].cast<double>().cross(m.vertices[t[2]].cast<double>())) /
         6.0;
  return v;
}

TEST(TriangleMesh, CubeIsClosedWithOutwardNormals) {
  const TriangleMesh cube = Cube();
  EXPECT_TRUE(AnalyzeTopology(cube).closed());
  EXPECT_NEAR(SignedVolume(cube), 1000.0, 1e-9);
  const auto n = cube.FaceNormals();
  EXPECT_TRUE(n[0].isApprox(Eigen::Vector3f(0, 0, -1)));
  EXPECT_TRUE(n[2].isApprox(Eigen::Vector3f(0, 0, 1)));
}

class MeshRoundTrip : public ::testing::TestWithParam<std::pair<MeshFormat, const char*>> {};

TEST_P(MeshRoundTrip, KeepsShapeTopologyAndWinding) {
  TempDir dir;
  const std::string path = dir.File(GetParam().second);
  ASSERT_TRUE(WriteMesh(path, Cube(), GetParam().first).ok());
  auto back = ReadMesh(path);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->num_triangles(), 12u);
  EXPECT_EQ(back->vertices.size(), 8u) << "identical vertices merged";
  EXPECT_TRUE(AnalyzeTopology(*back).closed());
  EXPECT_NEAR(SignedVolume(*back), 1000.0, 1e-6);
}

INSTANTIATE_TEST_SUITE_P(Formats, MeshRoundTrip,
                         ::testing::Values(std::make_pair(MeshFormat::kStlBinary, "cube.stl"),
                                           std::make_pair(MeshFormat::kStlAscii, "cube_ascii.stl"),
                                           std::make_pair(MeshFormat::kObj, "cube.obj"),
                                           std::make_pair(MeshFormat::kPlyBinary, "cube.ply"),
                                           std::make_pair(MeshFormat::kPlyAscii,
                                                          "cube_ascii.ply")));

// An ASCII STL of `m` with its keywords spelled by `kw` (solid, facet
// normal, outer loop, vertex, endloop, endfacet, endsolid), the solid's name
// and the numbers alike in every spelling.
std::string AsciiStl(const TriangleMesh& m, const std::vector<std::string>& kw) {
  std::string s = kw[0] + " Bracket_Rev facet\n";
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const Eigen::Vector3f n = m.FaceNormals()[t];
    s += " " + kw[1] + " " + std::to_string(n.x()) + " " + std::to_string(n.y()) + " " +
         std::to_string(n.z()) + "\n  " + kw[2] + "\n";
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector3f& v = m.vertices[m.triangles[t][c]];
      s += "   " + kw[3] + " " + std::to_string(v.x()) + " " + std::to_string(v.y()) + " " +
           std::to_string(v.z()) + "\n";
    }
    s += "  " + kw[4] + "\n " + kw[5] + "\n";
  }
  return s + kw[6] + " Bracket_Rev facet\n";
}

// Assimp 5.2 reads "FACET NORMAL" as no facet and "SOLID" as no STL; the
// reader hands it the keywords in lower case, so every spelling gives the
// same mesh.
TEST(ReadMesh, AsciiStlKeywordsInAnyCaseGiveTheSameMesh) {
  TempDir dir;
  const TriangleMesh cube = Cube();
  WriteBytes(dir.File("lower.stl"), AsciiStl(cube, {"solid", "facet normal", "outer loop", "vertex",
                                                    "endloop", "endfacet", "endsolid"}));
  WriteBytes(dir.File("upper.stl"), AsciiStl(cube, {"SOLID", "FACET NORMAL", "OUTER LOOP", "VERTEX",
                                                    "ENDLOOP", "ENDFACET", "ENDSOLID"}));
  WriteBytes(dir.File("mixed.stl"), AsciiStl(cube, {"Solid", "Facet Normal", "Outer Loop", "Vertex",
                                                    "EndLoop", "EndFacet", "EndSolid"}));
  auto lower = ReadMesh(dir.File("lower.stl"));
  ASSERT_TRUE(lower.ok()) << lower.status();
  ASSERT_EQ(lower->num_triangles(), 12u);
  EXPECT_EQ(lower->vertices.size(), 8u);
  for (const char* name : {"upper.stl", "mixed.stl"}) {
    SCOPED_TRACE(name);
    auto other = ReadMesh(dir.File(name));
    ASSERT_TRUE(other.ok()) << other.status();
    ASSERT_EQ(other->vertices.size(), lower->vertices.size());
    for (std::size_t v = 0; v < lower->vertices.size(); ++v)
      EXPECT_EQ(other->vertices[v], lower->vertices[v]) << "vertex " << v;
    EXPECT_EQ(other->triangles, lower->triangles);
  }
}

TEST(ReadMesh, Off) {
  TempDir dir;
  WriteBytes(dir.File("t.off"), "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n");
  auto m = ReadMesh(dir.File("t.off"));
  ASSERT_TRUE(m.ok()) << m.status();
  EXPECT_EQ(m->num_triangles(), 2u);
  EXPECT_EQ(AnalyzeTopology(*m).boundary_edges, 4u);
}

TEST(ReadMesh, KeepsSomeDegenerateTriangles) {
  TempDir dir;
  WriteBytes(dir.File("d.off"), "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n2 0 0\n3 0 1 2\n3 0 1 3\n");
  auto m = ReadMesh(dir.File("d.off"));
  ASSERT_TRUE(m.ok()) << m.status();
  EXPECT_EQ(m->CountDegenerate(), 1u);
}

struct BadMesh {
  const char* name;
  const char* file;
  std::string bytes;
  const char* message_part;
};

std::string BinaryStlHeader(uint32_t declared) {
  std::string s(80, ' ');
  s.append(reinterpret_cast<const char*>(&declared), 4);
  return s;
}

class MalformedMesh : public ::testing::TestWithParam<BadMesh> {};

TEST_P(MalformedMesh, GivesClearError) {
  TempDir dir;
  const std::string path = dir.File(GetParam().file);
  WriteBytes(path, GetParam().bytes);
  auto m = ReadMesh(path);
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.status().message().find(GetParam().message_part), std::string::npos) << m.status();
  EXPECT_NE(m.status().message().find(path), std::string::npos) << "names the file";
}

INSTANTIATE_TEST_SUITE_P(
    Files, MalformedMesh,
    ::testing::Values(
        BadMesh{"empty", "e.stl", "", "empty"},
        BadMesh{"truncated_binary_stl", "t.stl", BinaryStlHeader(1000) + std::string(100, 'x'),
                "cannot import"},
        BadMesh{"nan_vertex", "n.off", "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n",
                "not finite"},
        BadMesh{"only_degenerate", "d.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n2 0 0\n3 0 1 2\n",
                "degenerate"},
        BadMesh{"index_out_of_range", "i.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
                "cannot import"},
        BadMesh{"points_only", "p.ply",
                "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                "property float z\nend_header\n0 0 0\n1 1 1\n",
                "cannot import"},
        BadMesh{"garbage", "g.stl", std::string("solid x\nfacet normal oops\n"), "cannot import"}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(ReadMesh, MissingFileIsNotFound) {
  auto m = ReadMesh("/nonexistent/part.stl");
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.status().code(), absl::StatusCode::kNotFound);
}

TEST(WriteMesh, RefusesInvalidMesh) {
  TempDir dir;
  TriangleMesh bad = Cube();
  bad.triangles.push_back({0, 1, 99});
  EXPECT_FALSE(WriteMesh(dir.File("bad.stl"), bad).ok());
  EXPECT_TRUE(testing::ReadBytes(dir.File("bad.stl")).empty());
}

}  // namespace
}  // namespace surfinspect

namespace surfinspect {
namespace {

TEST(PlyDeclaresFaces, OnlyAFaceElementWithRowsMakesAMesh) {
  testing::TempDir dir;
  const std::string v = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
  const std::string f = "property list uchar int vertex_indices\n";
  WriteBytes(dir.File("m.ply"),
             "ply\nformat ascii 1.0\n" + v + "element face 1\n" + f + "end_header\n");
  WriteBytes(dir.File("c.ply"),
             "ply\nformat ascii 1.0\n" + v + "element face 0\n" + f + "end_header\n");
  WriteBytes(dir.File("p.ply"), "ply\nformat ascii 1.0\n" + v + "end_header\n");
  WriteBytes(dir.File("bad.ply"), "ply\nformat ascii 1.0\n" + v + "element face 1\n" + f);
  EXPECT_TRUE(PlyDeclaresFaces(dir.File("m.ply")));
  EXPECT_FALSE(PlyDeclaresFaces(dir.File("c.ply")));
  EXPECT_FALSE(PlyDeclaresFaces(dir.File("p.ply")));
  EXPECT_FALSE(PlyDeclaresFaces(dir.File("bad.ply")));
  EXPECT_FALSE(PlyDeclaresFaces(dir.File("missing.ply")));
}

}  // namespace
}  // namespace surfinspect
