#include "core/io/mesh_hash.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <string>

#include "tests/support/temp_dir.h"
#include "tests/support/test_meshes.h"

namespace surfinspect {
namespace {

void AppendLittleEndian(std::string& out, uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out += static_cast<char>((v >> (8 * i)) & 0xff);
}

void AppendFloat(std::string& out, float f) {
  uint32_t bits;
  std::memcpy(&bits, &f, 4);
  AppendLittleEndian(out, bits, 4);
}

// The wire layout, byte by byte: float32 xyz per vertex, uint32 per index.
std::string VertexBytes(const TriangleMesh& m) {
  std::string out;
  for (const auto& v : m.vertices)
    for (int k = 0; k < 3; ++k) AppendFloat(out, v[k]);
  return out;
}
std::string TriangleBytes(const TriangleMesh& m) {
  std::string out;
  for (const auto& t : m.triangles)
    for (uint32_t i : t) AppendLittleEndian(out, i, 4);
  return out;
}

// The canonical bytes as mesh_hash.h documents them.
std::string CanonicalBytes(const TriangleMesh& m) {
  std::string out("surfinspect.mesh.v1", 19);
  out += '\0';
  AppendLittleEndian(out, m.vertices.size(), 8);
  AppendLittleEndian(out, m.triangles.size(), 8);
  return out + VertexBytes(m) + TriangleBytes(m);
}

// coreutils' sha256sum of the bytes: an implementation that shares nothing
// with the one under test.
std::string Sha256sum(const std::string& bytes) {
  testing::TempDir dir;
  testing::WriteBytes(dir.File("canonical.bin"), bytes);
  const std::string cmd = "sha256sum '" + dir.File("canonical.bin") + "'";
  FILE* pipe = ::popen(cmd.c_str(), "r");
  if (!pipe) return "popen failed";
  char buf[65] = {};
  const std::size_t n = std::fread(buf, 1, 64, pipe);
  ::pclose(pipe);
  return std::string(buf, n);
}

TEST(MeshHash, IsTheSha256OfTheDocumentedCanonicalBytes) {
  const TriangleMesh sphere = testing::Icosphere(12.5, 2);
  const std::string expected = Sha256sum(CanonicalBytes(sphere));
  ASSERT_EQ(expected.size(), 64u) << expected;
  EXPECT_EQ(MeshSha256(sphere), expected);

  TriangleMesh empty;
  EXPECT_EQ(MeshSha256(empty), Sha256sum(CanonicalBytes(empty)));
}

TEST(MeshHash, BothOverloadsAgree) {
  for (const TriangleMesh& m : {testing::Box(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 2, 3)),
                                testing::Torus(50, 10, 24, 12), TriangleMesh{}}) {
    const std::string from_mesh = MeshSha256(m);
    EXPECT_EQ(MeshSha256(VertexBytes(m), TriangleBytes(m)), from_mesh);
    EXPECT_EQ(from_mesh.size(), 64u);
    EXPECT_EQ(from_mesh.find_first_not_of("0123456789abcdef"), std::string::npos) << from_mesh;
  }
}

TEST(MeshHash, AnyChangeToTheMeshChangesTheHash) {
  const TriangleMesh box = testing::Box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(10));
  const std::string h = MeshSha256(box);
  TriangleMesh moved = box;
  moved.vertices[3].x() = std::nextafter(moved.vertices[3].x(), 100.0f);  // one ulp
  EXPECT_NE(MeshSha256(moved), h);
  TriangleMesh reordered = box;
  std::swap(reordered.triangles[0], reordered.triangles[1]);
  EXPECT_NE(MeshSha256(reordered), h);
  TriangleMesh flipped = box;
  std::swap(flipped.triangles[0][1], flipped.triangles[0][2]);
  EXPECT_NE(MeshSha256(flipped), h);
  // The counts are hashed: moving bytes from the vertex to the triangle
  // buffer gives a different hash even though the concatenation is equal.
  const std::string v = VertexBytes(box), t = TriangleBytes(box);
  EXPECT_NE(MeshSha256(v.substr(0, v.size() - 12), v.substr(v.size() - 12) + t), h);
}

}  // namespace
}  // namespace surfinspect
