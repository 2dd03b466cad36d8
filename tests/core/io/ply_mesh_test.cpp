#include "core/io/ply_mesh.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

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

// A binary little-endian PLY: vertices (x y z float, then `extra` float
// properties) and faces given as (count, indices...) with int32 indices.
std::string BinaryPly(const std::vector<float>& xyz, int extra,
                      const std::vector<std::vector<int32_t>>& faces, const char* index = "int") {
  std::string out = "ply\nformat binary_little_endian 1.0\nelement vertex " +
                    std::to_string(xyz.size() / 3) +
                    "\nproperty float x\nproperty float y\nproperty float z\n";
  for (int e = 0; e < extra; ++e) out += "property float q" + std::to_string(e) + "\n";
  out += "element face " + std::to_string(faces.size()) + "\nproperty list uchar " + index +
         " vertex_indices\nend_header\n";
  for (std::size_t v = 0; v < xyz.size() / 3; ++v) {
    out.append(reinterpret_cast<const char*>(&xyz[3 * v]), 12);
    for (int e = 0; e < extra; ++e) out.append(4, '\x7f');
  }
  for (const auto& f : faces) {
    out += static_cast<char>(f.size());
    out.append(reinterpret_cast<const char*>(f.data()), 4 * f.size());
  }
  return out;
}

// The same file in ascii: read row by row, so it is the oracle of the
// binary reading in one pass.
std::string AsciiPly(const std::vector<float>& xyz,
                     const std::vector<std::vector<int32_t>>& faces) {
  std::string out = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(xyz.size() / 3) +
                    "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                    std::to_string(faces.size()) +
                    "\nproperty list uchar int vertex_indices\nend_header\n";
  char buf[64];
  for (std::size_t v = 0; v < xyz.size() / 3; ++v) {
    std::snprintf(buf, sizeof buf, "%.9g %.9g %.9g\n", xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]);
    out += buf;
  }
  for (const auto& f : faces) {
    out += std::to_string(f.size());
    for (int32_t i : f) out += " " + std::to_string(i);
    out += "\n";
  }
  return out;
}

TEST(ParsePlyMesh, BinaryInOnePassEqualsTheRowByRowReading) {
  std::vector<float> xyz;
  std::vector<std::vector<int32_t>> faces;
  const int n = 40;  // a grid of n x n vertices, quads and triangles mixed
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c)
      for (float v : {0.25f * c, 0.5f * r, 0.01f * static_cast<float>((r * c) % 7)})
        xyz.push_back(v);
  for (int r = 0; r + 1 < n; ++r)
    for (int c = 0; c + 1 < n; ++c) {
      const int32_t a = r * n + c, b = a + 1, d = a + n, e = d + 1;
      if ((r + c) % 3 == 0) {
        faces.push_back({a, b, e, d});
      } else {
        faces.push_back({a, b, e});
        faces.push_back({a, e, d});
      }
    }
  auto oracle = ParsePlyMesh(AsciiPly(xyz, faces), {}, "a.ply");
  ASSERT_TRUE(oracle.ok()) << oracle.status();
  for (int extra : {0, 2})
    for (const char* index : {"int", "uint"}) {
      auto m = ParsePlyMesh(BinaryPly(xyz, extra, faces, index), {}, "b.ply");
      ASSERT_TRUE(m.ok()) << m.status();
      EXPECT_EQ(m->vertices, oracle->vertices) << extra << index;
      EXPECT_EQ(m->triangles, oracle->triangles) << extra << index;
    }
}

TEST(ParsePlyMesh, BinaryFacesAreRefusedAsRowByRowWithTheirNumber) {
  const std::vector<float> xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  auto refused = [&](std::vector<std::vector<int32_t>> faces, const char* part) {
    std::string bytes = BinaryPly(xyz, 0, faces);
    ExpectRefused(bytes, part);
  };
  refused({{0, 1, 2}, {0, 1, 2}, {0, 1, 2, 3, 0}}, "face 2 has 5 corners");
  refused({{0, 1, 2}, {0, 1}}, "face 1 has 2 indices");
  refused({{0, 1, 2}, {1, 2, 3}, {0, 1, 4}}, "face 2: vertex index 4 out of range");
  refused({{0, 1, 2}, {0, -1, 2}}, "face 1: vertex index -1 out of range");
  std::string cut = BinaryPly(xyz, 0, {{0, 1, 2}, {1, 2, 3}});
  cut.resize(cut.size() - 2);
  ExpectRefused(cut, "face 1: truncated data section");
  std::string short_vertices = BinaryPly(xyz, 0, {{0, 1, 2}});
  short_vertices.resize(short_vertices.size() - 13 - 20);  // the face and 20 vertex bytes
  ExpectRefused(short_vertices, "truncated");
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
