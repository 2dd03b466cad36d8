#include "core/io/mesh_precheck.h"

#include <gtest/gtest.h>

#include <cstring>

namespace surfinspect {
namespace {

void ExpectRefused(const absl::Status& st, const char* name, const char* part) {
  ASSERT_FALSE(st.ok()) << part;
  EXPECT_NE(st.message().find(part), std::string::npos) << st;
  EXPECT_EQ(st.message().rfind(std::string(name) + ": cannot import: ", 0), 0u) << st;
}

std::string Facet(int vertices) {
  std::string s = " facet normal 0 0 1\n  outer loop\n";
  for (int i = 0; i < vertices; ++i)
    s += "   vertex " + std::to_string(i) + " 0 " + std::to_string(i * i) + "\n";
  return s + "  endloop\n endfacet\n";
}

std::string BinaryStl(uint32_t declared, std::size_t triangles) {
  std::string s(80, ' ');
  s.append(reinterpret_cast<const char*>(&declared), 4);
  return s + std::string(50 * triangles, '\0');
}

TEST(CheckStl, AcceptsWellFormedAsciiAndExactBinary) {
  EXPECT_TRUE(CheckStl("solid a\n" + Facet(3) + Facet(3) + "endsolid a\nsolid b\n" + Facet(3) +
                       "endsolid\n")
                  .ok());
  EXPECT_TRUE(CheckStl(BinaryStl(2, 2)).ok());
  // "solid" in a binary header does not make it ASCII when the size fits.
  std::string b = BinaryStl(1, 1);
  std::memcpy(b.data(), "solid", 5);
  EXPECT_TRUE(CheckStl(b).ok());
}

TEST(CheckStl, RefusesWithTheFacetAndTheReason) {
  ExpectRefused(CheckStl("solid a\n" + Facet(3) + Facet(4) + "endsolid a\n", {}, "p.stl"), "p.stl",
                "facet 1 (line 15): has 4 vertices (a facet needs exactly 3)");
  ExpectRefused(CheckStl("solid a\n" + Facet(2) + "endsolid a\n", {}, "p.stl"), "p.stl",
                "has 2 vertices");
  ExpectRefused(CheckStl("solid x\nfacet normal oops\n", {}, "p.stl"), "p.stl",
                "expected 'normal' and 3 numbers");
  ExpectRefused(CheckStl("solid x\n" + Facet(3), {}, "p.stl"), "p.stl", "without 'endsolid'");
  ExpectRefused(CheckStl("solid x\n vertex 1 2 3\nendsolid\n", {}, "p.stl"), "p.stl",
                "expected 'facet' or 'endsolid'");
  ExpectRefused(CheckStl(BinaryStl(1000, 2), {}, "p.stl"), "p.stl",
                "neither ASCII STL (no 'solid' at the start) nor binary STL: size 184 does not "
                "match 84 + 50 * 1000 = 50084");
  ExpectRefused(CheckStl("abc", {}, "p.stl"), "p.stl", "size 3 is under the 84-byte header");
  MeshReadLimits limits;
  limits.max_triangles = 1;
  EXPECT_EQ(CheckStl(BinaryStl(2, 2), limits).code(), absl::StatusCode::kResourceExhausted);
  EXPECT_EQ(CheckStl("solid a\n" + Facet(3) + Facet(3) + "endsolid a\n", limits).code(),
            absl::StatusCode::kResourceExhausted);
}

TEST(CheckStl, AcceptsKeywordsInAnyCaseAndLowerCasesOnlyThemForAssimp) {
  // The solid's name holds keywords and the numbers an upper-case exponent:
  // both stay as they are.
  const std::string shouted =
      "\n  SOLID Part FACET Vertex\r\n FACET NORMAL 0 0 1E+0\n  OUTER Loop\n   VERTEX 0 0 0\n"
      "   Vertex 1E+1 0 0\n   vErTeX 0 1e1 0\n  ENDLOOP\n ENDFACET\nENDSOLID Part FACET\n";
  const std::string lowered =
      "\n  solid Part FACET Vertex\r\n facet normal 0 0 1E+0\n  outer loop\n   vertex 0 0 0\n"
      "   vertex 1E+1 0 0\n   vertex 0 1e1 0\n  endloop\n endfacet\nendsolid Part FACET\n";
  EXPECT_TRUE(CheckStl(shouted).ok());
  std::string bytes = shouted;
  ASSERT_TRUE(CheckStlForAssimp(&bytes).ok());
  EXPECT_EQ(bytes, lowered);
  ExpectRefused(CheckStl("SOLID a\n" + Facet(3) + Facet(4) + "ENDSOLID a\n", {}, "p.stl"), "p.stl",
                "facet 1 (line 15): has 4 vertices");
  // A binary STL is left as it is, even with keywords in its header.
  std::string binary = BinaryStl(1, 1);
  std::memcpy(binary.data(), "SOLID FACET", 11);
  bytes = binary;
  ASSERT_TRUE(CheckStlForAssimp(&bytes).ok());
  EXPECT_EQ(bytes, binary);
}

// A file that starts with "solid" but is neither a valid ASCII STL nor a
// binary STL of its size: both readings are named.
TEST(CheckStl, NamesBothReadingsOfANearMiss) {
  std::string binary = BinaryStl(3, 2);  // 184 bytes for 3 declared triangles
  std::memcpy(binary.data(), "solid exported by CAD", 21);
  ExpectRefused(CheckStl(binary, {}, "p.stl"), "p.stl",
                "as ASCII STL: ends without 'endsolid'; as binary STL: size 184 does not match "
                "84 + 50 * 3 = 234");
  ExpectRefused(CheckStl("Solid x\n", {}, "p.stl"), "p.stl",
                "as ASCII STL: ends without 'endsolid'; as binary STL: size 8 is under the "
                "84-byte header");
  ExpectRefused(CheckStl("solid x\nfacet normal oops\n" + std::string(100, ' '), {}, "p.stl"),
                "p.stl",
                "as ASCII STL: facet 0 (line 2): expected 'normal' and 3 numbers; as binary STL: "
                "size 126 does not match 84 + 50 * 538976288 = 26948814484");
}

// Only polygonal statements pass; one that merely starts like a known one
// ("v0\xff...", which made Assimp run past a 5 s fuzzing timeout) is refused.
TEST(CheckObj, RefusesStatementsOutsidePolygonalObj) {
  const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  EXPECT_TRUE(CheckObj("mtllib a.mtl\no part\ns 1\nvp 0.5\n" + v + "f 1 2 3\n").ok());
  ExpectRefused(CheckObj(v + "v0\xff\xff\xff\xff 2 9\n", {}, "p.obj"), "p.obj",
                "line 4: unsupported statement 'v0");
  ExpectRefused(CheckObj(v + "curv 0 1 1 2\n", {}, "p.obj"), "p.obj",
                "unsupported statement 'curv'");
  ExpectRefused(CheckObj(v + "vp a\n", {}, "p.obj"), "p.obj", "bad number 'a'");
}

TEST(CheckObj, ChecksIndicesAgainstWhatTheFileDeclares) {
  const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  EXPECT_TRUE(
      CheckObj(v + "vt 0 0\nvn 0 0 1\n# c\ng x\nusemtl m\nf 1/1/1 2/1/1 3//1\nf -3 -2 -1\nl 1 2\n")
          .ok());
  EXPECT_TRUE(CheckObj("f 1 2 3\n" + v).ok()) << "forward references resolve at the end";
  ExpectRefused(CheckObj(v + "f 1 2 9\n", {}, "p.obj"), "p.obj",
                "line 4: vertex index '9' out of range (3 vertices");
  ExpectRefused(CheckObj(v + "f 1 2 0\n", {}, "p.obj"), "p.obj", "vertex index '0'");
  ExpectRefused(CheckObj("v 0 0 0\nf -1 -2 -3\n" + v, {}, "p.obj"), "p.obj",
                "line 2: vertex index '-2'");
  ExpectRefused(CheckObj(v + "f 1/2 2 3\n", {}, "p.obj"), "p.obj", "vertex index '1/2'");
  ExpectRefused(CheckObj(v + "f\n", {}, "p.obj"), "p.obj", "'f' without indices");
  ExpectRefused(CheckObj(v + "f 1 2\n", {}, "p.obj"), "p.obj", "a face has 2 indices");
  std::string big = v + "f";
  for (int i = 0; i < 1001; ++i) big += " 1";
  ExpectRefused(CheckObj(big + "\n", {}, "p.obj"), "p.obj", "1001 corners, over 1000");
  ExpectRefused(CheckObj("v 0 0\n", {}, "p.obj"), "p.obj", "'v' needs 3 to 7 numbers");
  ExpectRefused(CheckObj("v 0 0 z\n", {}, "p.obj"), "p.obj", "bad number 'z'");
  ExpectRefused(CheckObj("# nothing\n", {}, "p.obj"), "p.obj", "no vertices");
  MeshReadLimits limits;
  limits.max_triangles = 1;
  EXPECT_EQ(CheckObj(v + "f 1 2 3\nf 1 2 3\n", limits).code(),
            absl::StatusCode::kResourceExhausted);
}

}  // namespace
}  // namespace surfinspect
