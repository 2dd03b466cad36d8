#include "core/io/off_format.h"

#include <gtest/gtest.h>

namespace surfinspect {
namespace {

void ExpectRefused(const std::string& bytes, const char* part,
                   absl::StatusCode code = absl::StatusCode::kInvalidArgument) {
  auto m = ParseOff(bytes, {}, "part.off");
  ASSERT_FALSE(m.ok()) << part;
  EXPECT_EQ(m.status().code(), code) << m.status();
  EXPECT_NE(m.status().message().find(part), std::string::npos) << m.status();
  EXPECT_EQ(m.status().message().rfind("part.off: ", 0), 0u) << m.status();
}

const std::string kVerts = "0 0 0\n1 0 0\n0 1 0\n";

TEST(ParseOff, RefusesHeadersBeforeAllocating) {
  ExpectRefused("OFF\n999999999 999999999 0\n", "999999999 faces exceed the limit",
                absl::StatusCode::kResourceExhausted);
  ExpectRefused("OFF\n999999999 9 0\n", "more than the file's 0 remaining bytes can hold");
  ExpectRefused("OFF\n18446744073709551615 1 0\n" + kVerts, "can hold");
  ExpectRefused("OFF\n3 60000000 0\n", "exceed the limit", absl::StatusCode::kResourceExhausted);
  ExpectRefused("3 1 0\n" + kVerts + "3 0 1 2\n", "no OFF keyword");
  ExpectRefused("OFF BINARY\n", "binary OFF");
  ExpectRefused("OFF\n3 1\n" + kVerts + "3 0 1 2\n", "three integers");
  ExpectRefused("OFF\n0 1 0\n3 0 1 2\n", "no vertices");
  ExpectRefused("OFF\n3 0 0\n" + kVerts, "no faces");
  ExpectRefused("OFF\n", "no counts");
}

TEST(ParseOff, RefusesBadBodies) {
  const std::string h = "OFF\n3 1 0\n";
  ExpectRefused(h + kVerts + "0\n", "face 0 has 0 indices");
  ExpectRefused(h + kVerts + "2 0 1\n", "face 0 has 2 indices");
  ExpectRefused(h + kVerts + "5 0 1 2 0 1\n", "face 0 has 5 corners");
  ExpectRefused(h + kVerts + "3 0 1 3\n", "vertex index '3' out of range");
  ExpectRefused(h + kVerts + "3 0 1\n", "lists fewer indices");
  ExpectRefused(h + kVerts + "3 0 1 2 red\n", "bad colour");
  ExpectRefused(h + "0 0 0\n1 0\n0 1 0\n3 0 1 2\n", "vertex 1: bad coordinates");
  ExpectRefused(h + "0 0 0\n1 0 0\n0 1 q\n3 0 1 2\n", "vertex 2: bad coordinates");
  ExpectRefused("OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n", "2 faces declared, 1 found");
  ExpectRefused("OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n# a comment that pads the file\n",
                "4 vertices declared, 3 found");
}

TEST(ParseOff, ReadsCommentsColoursQuadsAndCountsOnTheKeywordLine) {
  auto m = ParseOff(
      "# made by hand\nCOFF 5 2 0\n0 0 0 1 0 0 1\n1 0 0 1 0 0 1\n1 1 0 1 0 0 1 # c\n"
      "0 1 0 1 0 0 1\n0.2 0.2 0 1 0 0 1\n\n4 0 1 2 3\n4 0 1 4 3 0.5 0.5 0.5\n");
  ASSERT_TRUE(m.ok()) << m.status();
  EXPECT_EQ(m->vertices.size(), 5u);
  // The convex quad fans from corner 0; the concave one (corner 4 = (0.2, 0.2)) from there.
  const std::vector<Triangle> expected = {{0, 1, 2}, {0, 2, 3}, {4, 3, 0}, {4, 0, 1}};
  EXPECT_EQ(m->triangles, expected);
}

}  // namespace
}  // namespace surfinspect
