#include "core/io/ply_mesh.h"

#include <gtest/gtest.h>

#include "core/io/io_mesh.h"
#include "tests/support/temp_dir.h"

namespace surfinspect {
namespace {

const std::string kHead =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
    "0 0 0\n1 0 0\n0 1 0\n";

void ExpectRefused(const std::string& bytes, const char* part) {
  auto m = ParsePlyMesh(bytes, {}, "part.ply");
  ASSERT_FALSE(m.ok()) << part;
  EXPECT_NE(m.status().message().find(part), std::string::npos) << m.status();
  EXPECT_EQ(m.status().message().rfind("part.ply: ", 0), 0u) << m.status();
}

TEST(ParsePlyMesh, RefusesBadFacesWithTheirNumber) {
  ExpectRefused(kHead + "0\n", "face 0 has 0 indices");
  ExpectRefused(kHead + "1 0\n", "face 0 has 1 indices");
  ExpectRefused(kHead + "2 0 1\n", "face 0 has 2 indices");
  ExpectRefused(kHead + "5 0 1 2 0 1\n", "face 0 has 5 corners");
  ExpectRefused(kHead + "3 0 1 3\n", "face 0: vertex index 3 out of range");
  ExpectRefused(kHead + "3 0 1 -1\n", "face 0: vertex index -1 out of range");
  ExpectRefused(kHead + "3 0 1\n", "too few values");
  ExpectRefused(kHead + "3 0 1 2 7\n", "1 values more");
  ExpectRefused(kHead.substr(0, kHead.find("end_header")), "no 'end_header'");
  ExpectRefused(kHead.substr(0, kHead.find("end_header")) + "0 0 0\n", "unknown line '0 0 0'");
  ExpectRefused(kHead.substr(0, kHead.rfind("0 1 0\n")),
                "truncated: element vertex declares 3 rows, 2 found");
}

TEST(ParsePlyMesh, RefusesFilesWithoutASurface) {
  ExpectRefused(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n0 0 0\n",
      "no faces");
  ExpectRefused(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "element face 0\nproperty list uchar int vertex_indices\nend_header\n0 0\n",
      "no faces");
  ExpectRefused(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0\n3 0 0 0\n",
      "no 'z' property");
  ExpectRefused(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar float vertex_indices\n"
      "end_header\n0 0 0\n3 0 0 0\n",
      "integer vertex_indices");
}

TEST(ParsePlyMesh, FaceCountOverTheLimitIsResourceExhausted) {
  MeshReadLimits limits;
  limits.max_triangles = 10;
  auto m = ParsePlyMesh(
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 11\nproperty list uchar int vertex_indices\nend_header\n",
      limits, "p.ply");
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.status().code(), absl::StatusCode::kResourceExhausted) << m.status();
}

// The writers' PLY (Assimp's exporter) read back by our parser, both encodings.
TEST(ParsePlyMesh, ReadsBinaryAndAsciiWrittenByTheExporterIdentically) {
  TriangleMesh cube;
  for (int i = 0; i < 8; ++i)
    cube.vertices.emplace_back(10.f * (i & 1) + 0.1f, 10.f * ((i >> 1) & 1), 10.f * ((i >> 2) & 1));
  cube.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                    {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  testing::TempDir dir;
  std::vector<TriangleMesh> back;
  for (MeshFormat f : {MeshFormat::kPlyBinary, MeshFormat::kPlyAscii}) {
    ASSERT_TRUE(WriteMesh(dir.File("c.ply"), cube, f).ok());
    auto m = ParsePlyMesh(testing::ReadBytes(dir.File("c.ply")));
    ASSERT_TRUE(m.ok()) << m.status();
    back.push_back(*m);
  }
  ASSERT_EQ(back[0].vertices.size(), 8u);
  EXPECT_EQ(back[0].vertices, back[1].vertices);
  EXPECT_EQ(back[0].triangles, back[1].triangles);
  EXPECT_EQ(back[0].num_triangles(), 12u);
}

}  // namespace
}  // namespace surfinspect
