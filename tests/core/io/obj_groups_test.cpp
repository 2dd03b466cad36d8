// ObjGroups (core/io/obj_groups.cpp) through ReadMeshGroups: each triangle
// that Assimp imported lands in the group its face was written in. The
// oracle is geometric: every group's faces are written at their own x, so a
// triangle's centroid tells which group it must be in.
#include "core/io/obj_groups.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/io/io_mesh.h"
#include "tests/support/temp_dir.h"

namespace surfinspect {
namespace {

// A unit square (two triangles as a quad, or one pentagon = 3 triangles) at
// x offset `x`, with vertices written just before the face.
std::string Quad(double x) {
  const std::string X0 = std::to_string(x), X1 = std::to_string(x + 1);
  return "v " + X0 + " 0 0\nv " + X1 + " 0 0\nv " + X1 + " 1 0\nv " + X0 + " 1 0\nf -4 -3 -2 -1\n";
}
std::string Pentagon(double x) {
  const std::string X0 = std::to_string(x), X1 = std::to_string(x + 1),
                    XM = std::to_string(x + 0.5);
  return "v " + X0 + " 0 0\nv " + X1 + " 0 0\nv " + X1 + " 1 0\nv " + XM + " 1.5 0\nv " + X0 +
         " 1 0\nf -5/1 -4/1 -3/1 -2/1 -1/1\n";
}

struct Read {
  TriangleMesh mesh;
  absl::StatusOr<MeshGroups> groups;
};

Read ReadObj(const std::string& text) {
  static testing::TempDir dir;
  static int n = 0;
  const std::string path = dir.File("m" + std::to_string(n++) + ".obj");
  testing::WriteBytes(path, "vt 0 0\n" + text);
  auto mesh = ReadMesh(path);
  EXPECT_TRUE(mesh.ok()) << mesh.status();
  Read r{mesh.ok() ? *mesh : TriangleMesh{}, absl::UnknownError("not read")};
  if (mesh.ok()) r.groups = ReadMeshGroups(path, r.mesh);
  return r;
}

// The x offset of the square a triangle came from: floor of its centroid's x.
int SquareOf(const TriangleMesh& m, std::size_t t) {
  float x = 0;
  for (int c = 0; c < 3; ++c) x += m.vertices[m.triangles[t][c]].x() / 3;
  return static_cast<int>(std::floor(x));
}

TEST(ObjGroups, EveryTriangleLandsInTheGroupOfItsFace) {
  // Squares at x = 0..5: none, a, b and extra, a (reopened), c (by `o`),
  // none (bare g). A `g` with several names puts its faces in each of them.
  const Read r = ReadObj(Quad(0) + "g a\n" + Quad(1) + "g b extra\n" + Pentagon(2) + "g a\n" +
                         Quad(3) + "o c\n" + Quad(4) + "g\n" + Quad(5));
  ASSERT_TRUE(r.groups.ok()) << r.groups.status();
  EXPECT_EQ(r.groups->names, (std::vector<std::string>{"a", "b", "extra", "c"}));
  ASSERT_EQ(r.groups->triangle_group.size(), r.mesh.num_triangles());
  ASSERT_EQ(r.mesh.num_triangles(), 2u * 5 + 3);
  const uint32_t none = MeshGroups::kNoGroup;
  const uint32_t expected[] = {none, 0, 1, 0, 3, none};
  std::size_t in_extra = 0;
  for (std::size_t t = 0; t < r.mesh.num_triangles(); ++t) {
    const int square = SquareOf(r.mesh, t);
    EXPECT_EQ(r.groups->triangle_group[t], expected[square]) << "triangle " << t;
    EXPECT_EQ(r.groups->Contains(static_cast<uint32_t>(t), 2), square == 2) << "triangle " << t;
    EXPECT_EQ(r.groups->Contains(static_cast<uint32_t>(t), 1), square == 2) << "triangle " << t;
    in_extra += r.groups->Contains(static_cast<uint32_t>(t), 2);
  }
  EXPECT_EQ(in_extra, 3u);
}

// surfinspect cad names colour groups `color:#rrggbb`: a '#' inside a name
// is part of it, a '#' that starts a token begins a comment.
TEST(ObjGroups, AHashInsideANameIsPartOfItAndStartsACommentOnlyAtATokensStart) {
  const Read r =
      ReadObj("g face:1 color:#ff0000 # the red face\n" + Quad(0) + "#g hidden\n" + Quad(1));
  ASSERT_TRUE(r.groups.ok()) << r.groups.status();
  EXPECT_EQ(r.groups->names, (std::vector<std::string>{"face:1", "color:#ff0000"}));
  for (std::size_t t = 0; t < r.mesh.num_triangles(); ++t)
    EXPECT_EQ(r.groups->Contains(static_cast<uint32_t>(t), 1), SquareOf(r.mesh, t) <= 1);
}

TEST(ObjGroups, FileWithoutGroupsHasNone) {
  const Read r = ReadObj(Quad(0) + Quad(1));
  ASSERT_TRUE(r.groups.ok()) << r.groups.status();
  EXPECT_TRUE(r.groups->names.empty());
  EXPECT_TRUE(r.groups->triangle_group.empty());
}

// Materials make Assimp split an object into meshes, which can reorder the
// faces: the groups are then either mapped exactly or refused, never wrong.
TEST(ObjGroups, MaterialsEitherMapExactlyOrAreRefusedByName) {
  const Read r = ReadObj("g a\nusemtl red\n" + Quad(0) + "usemtl blue\n" + Quad(1) +
                         "usemtl red\n" + Quad(2) + "g b\nusemtl blue\n" + Quad(3));
  if (!r.groups.ok()) {
    EXPECT_EQ(r.groups.status().code(), absl::StatusCode::kFailedPrecondition);
    EXPECT_NE(r.groups.status().message().find("cannot be mapped"), std::string::npos);
    return;
  }
  const uint32_t expected[] = {0, 0, 0, 1};
  for (std::size_t t = 0; t < r.mesh.num_triangles(); ++t)
    EXPECT_EQ(r.groups->triangle_group[t], expected[SquareOf(r.mesh, t)]) << "triangle " << t;
}

TEST(ObjGroups, OtherFormatsHaveNoGroups) {
  testing::TempDir dir;
  TriangleMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.triangles = {{0, 1, 2}};
  const std::string path = dir.File("t.stl");
  ASSERT_TRUE(WriteMesh(path, m).ok());
  auto groups = ReadMeshGroups(path, m);
  ASSERT_TRUE(groups.ok());
  EXPECT_TRUE(groups->names.empty());
}

}  // namespace
}  // namespace surfinspect
