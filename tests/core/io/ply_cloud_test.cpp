// Tests core/io/ply_format.cpp (the header parser), core/io/ply_rows.cpp
// (the row reader), through the cloud reader that uses them, and
// core/io/ply_cloud.cpp.
#include "core/io/ply_cloud.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "core/io/ply_format.h"

namespace surfinspect {
namespace {

const std::string kXyz = "property float x\nproperty float y\nproperty float z\n";

void ExpectRefused(const std::string& bytes, const char* part,
                   absl::StatusCode code = absl::StatusCode::kInvalidArgument) {
  auto c = ParsePlyCloud(bytes, {}, "scan.ply");
  ASSERT_FALSE(c.ok()) << part;
  EXPECT_EQ(c.status().code(), code) << c.status();
  EXPECT_NE(c.status().message().find(part), std::string::npos) << c.status();
  EXPECT_EQ(c.status().message().rfind("scan.ply: ", 0), 0u) << c.status();
}

TEST(ParsePlyHeader, RefusesEveryMalformedLine) {
  const std::string v = "element vertex 1\n" + kXyz;
  ExpectRefused("plx\n", "no 'ply' magic");
  ExpectRefused("ply\nelement vertex 1\n" + kXyz + "end_header\n1 2 3\n", "no format line");
  ExpectRefused("ply\nformat ascii 1.0\nformat ascii 1.0\n" + v + "end_header\n",
                "repeated format");
  ExpectRefused("ply\nformat binary 1.0\n" + v + "end_header\n", "unknown format 'binary'");
  ExpectRefused("ply\nformat ascii 2.0\n" + v + "end_header\n", "version must be 1.0");
  ExpectRefused("ply\nformat ascii 1.0\nproperty float x\n" + v + "end_header\n",
                "property before any element");
  ExpectRefused("ply\nformat ascii 1.0\n" + v + "property float x\nend_header\n",
                "repeated property 'x'");
  ExpectRefused("ply\nformat ascii 1.0\n" + v + v + "end_header\n", "repeated element vertex");
  ExpectRefused("ply\nformat ascii 1.0\nelement vertex 1x\n" + kXyz + "end_header\n",
                "bad element line");
  ExpectRefused("ply\nformat ascii 1.0\n" + v + "property list float int q\nend_header\n",
                "list length must be an integer");
  ExpectRefused("ply\nformat ascii 1.0\n" + v + "property list uchar quad q\nend_header\n",
                "bad list type");
  ExpectRefused("ply\nformat ascii 1.0\n" + v + "property float\nend_header\n",
                "bad property line");
  ExpectRefused("ply\nformat ascii 1.0\nobj_info num_cols x\n" + v + "end_header\n",
                "bad obj_info num_cols");
  ExpectRefused(
      "ply\nformat ascii 1.0\nobj_info num_rows 1\nobj_info num_rows 1\n" + v + "end_header\n",
      "repeated obj_info");
  ExpectRefused("ply\nformat ascii 1.0\n" + v + "element empty 3\nend_header\n1 2 3\n",
                "has rows but no properties");
  ExpectRefused("ply\nformat ascii 1.0\n" + v + "bogus\nend_header\n", "unknown line 'bogus'");
  ExpectRefused("ply\nformat ascii 1.0\nelement vertex 999999999999\n" + kXyz + "end_header\n",
                "over the limit", absl::StatusCode::kResourceExhausted);
}

TEST(ParsePlyCloud, RefusesGridsThatDisagreeWithTheVertices) {
  const std::string body = "element vertex 4\n" + kXyz + "end_header\n1 2 3\n4 5 6\n7 8 9\n1 1 1\n";
  ExpectRefused("ply\nformat ascii 1.0\nobj_info num_cols 2\nobj_info num_rows 1\n" + body,
                "grid 2 x 1 does not match the 4 vertices");
  ExpectRefused("ply\nformat ascii 1.0\nobj_info num_cols 3\nobj_info num_rows 2\n" + body,
                "grid 3 x 2 does not match the 4 vertices");
  EXPECT_TRUE(
      ParsePlyCloud("ply\nformat ascii 1.0\nobj_info num_cols 2\nobj_info num_rows 2\n" + body)
          .ok());
}

TEST(ParsePlyCloud, RefusesShortOrBadData) {
  const std::string h = "ply\nformat binary_little_endian 1.0\nelement vertex 10\n" + kXyz;
  ExpectRefused(h + "end_header\n" + std::string(12, '\0'),
                "truncated: declared elements need at least 120");
  ExpectRefused(h + "property list uint float extra\nend_header\n" + std::string(12, '\0') +
                    std::string("\xff\xff\xff\x0f", 4) + std::string(160, '\0'),
                "truncated data section");
  const std::string a = "ply\nformat ascii 1.0\nelement vertex 2\n" + kXyz + "end_header\n";
  ExpectRefused(a + "1 2 3\n", "declares 2 rows, 1 found");
  ExpectRefused(a + "1 2 3\n4 5 z\n", "bad value 'z' for z");
  ExpectRefused(a + "1 2 3\n4 5 6 7\n", "values more than its properties hold");
  ExpectRefused(a + "1 2 3\n4 5 1e\n", "bad number '1e'");
  ExpectRefused(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty int x\nproperty float y\nproperty float "
      "z\nend_header\n1 2 3\n",
      "field x must be float32 or float64");
  ExpectRefused(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 "
      "2\n",
      "no 'z' property");
  ExpectRefused(
      "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int "
      "vertex_indices\nend_header\n0\n",
      "no vertices");
}

TEST(ParsePlyCloud, ReadsEncodingsExtraPropertiesAndRangeGrids) {
  float vals[6] = {1.5f, -2.25f, 400.125f, NAN, 4.f, 5.f};
  std::string le(reinterpret_cast<const char*>(vals), 24), be;
  for (int i = 0; i < 24; i += 4) be += std::string{le[i + 3], le[i + 2], le[i + 1], le[i]};
  for (const auto& [format, data] :
       {std::pair<std::string, std::string>{"binary_little_endian", le},
        {"binary_big_endian", be}}) {
    auto c = ParsePlyCloud("ply\nformat " + format + " 1.0\nelement vertex 2\n" + kXyz +
                           "element face 0\nproperty list uchar int vertex_indices\nend_header\n" +
                           data);
    ASSERT_TRUE(c.ok()) << c.status();
    ASSERT_EQ(c->size(), 2u);
    EXPECT_EQ(0, std::memcmp(c->points.data(), vals, 24)) << format << ": NaN bits kept";
  }
  auto d = ParsePlyCloud(
      "ply\nformat ascii 1.0\ncomment x\nelement vertex 2\nproperty uchar red\nproperty double x\n"
      "property double y\nproperty double z\nproperty list uchar float n\nend_header\n"
      "7 0.1 2 3 2 8 9\n\n255 4 5 6 0\n");
  ASSERT_TRUE(d.ok()) << d.status();
  EXPECT_EQ(d->points[0], Eigen::Vector3f(static_cast<float>(0.1), 2, 3));
  EXPECT_EQ(d->points[1], Eigen::Vector3f(4, 5, 6));
  // PCL's organized PLY: a 2 x 2 range grid with one empty cell.
  auto g = ParsePlyCloud(
      "ply\nformat ascii 1.0\nobj_info num_cols 2\nobj_info num_rows 2\nelement vertex 3\n" + kXyz +
      "element range_grid 4\nproperty list uchar int vertex_indices\nend_header\n"
      "1 1 1\n2 2 2\n3 3 3\n1 0\n0\n1 2\n1 1\n");
  ASSERT_TRUE(g.ok()) << g.status();
  ASSERT_EQ(g->size(), 4u);
  EXPECT_EQ(g->points[0], Eigen::Vector3f(1, 1, 1));
  EXPECT_FALSE(PointCloud::IsValid(g->points[1]));
  EXPECT_EQ(g->points[2], Eigen::Vector3f(3, 3, 3));
  EXPECT_EQ(g->points[3], Eigen::Vector3f(2, 2, 2));
  ExpectRefused(
      "ply\nformat ascii 1.0\nobj_info num_cols 2\nobj_info num_rows 2\nelement vertex 3\n" + kXyz +
          "element range_grid 4\nproperty list uchar int vertex_indices\nend_header\n"
          "1 1 1\n2 2 2\n3 3 3\n1 0\n0\n1 3\n1 1\n",
      "range_grid 2: vertex index out of range");
}

}  // namespace
}  // namespace surfinspect
