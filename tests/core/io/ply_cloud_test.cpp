// Tests core/io/ply_format.cpp (the header parser), core/io/ply_rows.cpp
// (the row reader), through the cloud reader that uses them, and
// core/io/ply_cloud.cpp.
#include "core/io/ply_cloud.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

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
  EXPECT_EQ(g->width, 2u);
  EXPECT_EQ(g->height, 2u);
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

// The Stanford range-scan layout (bunny/data/bun000.ply: obj_info num_cols
// 512 / num_rows 400, a range_grid of 204800 cells), small: 4 columns, 3
// rows, cells 1, 6 and 11 empty, the vertices stored in reverse cell order.
// Cell r is row r / 4, column r % 4 and holds the point (column, row,
// 100 + r).
constexpr int kCols = 4, kRows = 3;
bool EmptyCell(int r) { return r == 1 || r == 6 || r == 11; }

std::string GridHeader(const std::string& format, int vertices) {
  return "ply\nformat " + format +
         " 1.0\ncomment a range scan\nobj_info num_cols 4\nobj_info num_rows 3\nelement vertex " +
         std::to_string(vertices) + "\n" + kXyz +
         "element range_grid 12\nproperty list uchar int vertex_indices\nend_header\n";
}

// (ascii, binary little-endian) files of the grid above.
std::pair<std::string, std::string> RangeGridFiles() {
  std::vector<int> cells;  // the valid cells, in vertex order
  for (int r = kCols * kRows - 1; r >= 0; --r)
    if (!EmptyCell(r)) cells.push_back(r);
  const int n = static_cast<int>(cells.size());
  std::string ascii = GridHeader("ascii", n), binary = GridHeader("binary_little_endian", n);
  for (int r : cells) {
    const float p[3] = {static_cast<float>(r % kCols), static_cast<float>(r / kCols), 100.f + r};
    ascii += std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "\n";
    binary.append(reinterpret_cast<const char*>(p), 12);
  }
  for (int r = 0; r < kCols * kRows; ++r) {
    const int32_t v =
        static_cast<int32_t>(std::find(cells.begin(), cells.end(), r) - cells.begin());
    ascii += EmptyCell(r) ? "0\n" : "1 " + std::to_string(v) + "\n";
    binary += EmptyCell(r) ? '\0' : '\1';
    if (!EmptyCell(r)) binary.append(reinterpret_cast<const char*>(&v), 4);
  }
  return {ascii, binary};
}

TEST(ParsePlyCloud, ReadsARangeGridAsAnOrganizedCloudRowByRow) {
  const auto [ascii, binary] = RangeGridFiles();
  for (const std::string& bytes : {ascii, binary}) {
    SCOPED_TRACE(bytes.substr(0, 30));
    auto c = ParsePlyCloud(bytes);
    ASSERT_TRUE(c.ok()) << c.status();
    EXPECT_TRUE(c->organized());
    EXPECT_EQ(c->width, 4u);
    EXPECT_EQ(c->height, 3u);
    ASSERT_EQ(c->size(), 12u);
    EXPECT_EQ(c->CountValid(), 9u);
    for (int r = 0; r < kCols * kRows; ++r) {
      if (EmptyCell(r)) {
        EXPECT_TRUE(std::isnan(c->points[r].x()) && std::isnan(c->points[r].y()) &&
                    std::isnan(c->points[r].z()))
            << "cell " << r;
      } else {
        EXPECT_EQ(c->points[r], Eigen::Vector3f(r % kCols, r / kCols, 100.f + r)) << "cell " << r;
      }
    }
  }
  // Without a range_grid, the vertices are the cells, in order.
  auto v = ParsePlyCloud(
      "ply\nformat ascii 1.0\nobj_info num_cols 2\nobj_info num_rows 3\n"
      "element vertex 6\n" +
      kXyz + "end_header\n" + "0 0 0\n1 0 1\nnan nan nan\n1 1 3\n0 2 4\n1 2 5\n");
  ASSERT_TRUE(v.ok()) << v.status();
  EXPECT_EQ(v->width, 2u);
  EXPECT_EQ(v->height, 3u);
  EXPECT_EQ(v->points[3], Eigen::Vector3f(1, 1, 3));
  EXPECT_FALSE(PointCloud::IsValid(v->points[2]));
  // One of the two alone leaves the cloud unorganized, as before.
  auto one = ParsePlyCloud("ply\nformat ascii 1.0\nobj_info num_cols 2\nelement vertex 2\n" + kXyz +
                           "end_header\n0 0 0\n1 0 1\n");
  ASSERT_TRUE(one.ok()) << one.status();
  EXPECT_FALSE(one->organized());
}

}  // namespace
}  // namespace surfinspect
