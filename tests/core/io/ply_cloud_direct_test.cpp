// Tests ReadPackedXyzPly (core/io/ply_cloud.cpp): the file read straight
// into the cloud gives what ParsePlyCloud gives on the file's bytes, the
// same points bit for bit or the same error, and every other layout is
// left to the general reader.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "core/io/io_point_cloud.h"
#include "core/io/ply_cloud.h"
#include "tests/support/temp_dir.h"

namespace surfinspect {
namespace {

using testing::TempDir;
using testing::WriteBytes;

const std::string kXyz = "property float x\nproperty float y\nproperty float z\n";

// Little-endian float32 rows: finite values, -0, NaN with payloads.
std::string Rows(std::size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-500.f, 500.f);
  std::string out(12 * n, '\0');
  for (std::size_t i = 0; i < 3 * n; ++i) {
    float f = u(rng);
    if (i % 97 == 5) f = -0.0f;
    uint32_t bits;
    std::memcpy(&bits, &f, 4);
    if (i % 89 == 7) bits = 0x7fc00000u | (static_cast<uint32_t>(i) & 0x3fffffu);  // NaN payload
    std::memcpy(&out[4 * i], &bits, 4);
  }
  return out;
}

std::string Header(const std::string& body, std::size_t n,
                   const std::string& format = "binary_little_endian") {
  return "ply\nformat " + format + " 1.0\n" + body + "element vertex " + std::to_string(n) + "\n" +
         kXyz;
}

// ReadPointCloud on the file against ParsePlyCloud on its bytes.
void ExpectSameAsGeneral(const std::string& path, const std::string& bytes,
                         const CloudReadLimits& limits = {}) {
  const absl::StatusOr<PointCloud> direct = ReadPointCloud(path, limits);
  const absl::StatusOr<PointCloud> general = ParsePlyCloud(bytes, limits, path);
  ASSERT_EQ(direct.ok(), general.ok()) << direct.status() << " vs " << general.status();
  if (!general.ok()) {
    EXPECT_EQ(direct.status(), general.status());
    return;
  }
  ASSERT_EQ(direct->width, general->width);
  ASSERT_EQ(direct->height, general->height);
  ASSERT_EQ(direct->size(), general->size());
  EXPECT_EQ(0, std::memcmp(direct->points.data(), general->points.data(), 12 * direct->size()));
}

struct Case {
  std::string name;
  std::string bytes;
  bool direct;  // whether ReadPackedXyzPly takes the file
};

std::vector<Case> Cases() {
  const std::size_t n = 1000;
  const std::string rows = Rows(n, 3);
  std::string inf = rows;
  const float infinity = INFINITY;
  std::memcpy(&inf[12 * 417 + 4], &infinity, 4);
  std::string long_header;
  for (int i = 0; i < 4000; ++i) long_header += "comment a header longer than the first read\n";
  const std::string pcl_grid = "obj_info num_cols " + std::to_string(n) + "\nobj_info num_rows 1\n";
  return {
      {"plain", Header("", n) + "end_header\n" + rows, true},
      {"our writer's",
       Header("comment PCL generated\n" + pcl_grid, n) +
           "element face 0\nproperty list uchar int vertex_indices\nend_header\n" + rows,
       true},
      {"empty range_grid",
       Header("", n) +
           "element range_grid 0\nproperty list uchar int "
           "vertex_indices\nend_header\n" +
           rows,
       true},
      {"trailing bytes", Header("", n) + "end_header\n" + rows + "trailing", true},
      {"one grid line", Header("obj_info num_cols 7\n", n) + "end_header\n" + rows, true},
      {"organized grid",
       Header("obj_info num_cols 40\nobj_info num_rows 25\n", n) + "end_header\n" + rows, true},
      {"infinite coordinate", Header("", n) + "end_header\n" + inf, true},
      {"grid of other size",
       Header("obj_info num_cols 10\nobj_info num_rows 10\n", n) + "end_header\n" + rows, false},
      {"truncated", Header("", n) + "end_header\n" + rows.substr(0, rows.size() - 1), false},
      {"big-endian", Header("", n, "binary_big_endian") + "end_header\n" + rows, false},
      {"ascii", "ply\nformat ascii 1.0\nelement vertex 2\n" + kXyz + "end_header\n1 2 3\n4 5 6\n",
       false},
      {"float64",
       "ply\nformat binary_little_endian 1.0\nelement vertex 500\nproperty double x\n"
       "property double y\nproperty double z\nend_header\n" +
           rows,
       false},
      {"y first",
       "ply\nformat binary_little_endian 1.0\nelement vertex 1000\nproperty float y\n"
       "property float x\nproperty float z\nend_header\n" +
           rows,
       false},
      {"a fourth property", Header("", 750) + "property float w\nend_header\n" + rows, false},
      {"rows after it",
       Header("", n - 10) +
           "element face 10\nproperty list uchar int "
           "vertex_indices\nend_header\n" +
           rows,
       false},
      {"no vertices", Header("", 0) + "end_header\n", false},
      {"long header", Header(long_header, n) + "end_header\n" + rows, false},
  };
}

TEST(ReadPackedXyzPly, GivesTheGeneralReadersCloudOrErrorAndOnlyTakesItsLayout) {
  TempDir dir;
  for (const Case& c : Cases()) {
    SCOPED_TRACE(c.name);
    const std::string path = dir.File("scan.ply");
    WriteBytes(path, c.bytes);
    EXPECT_EQ(ReadPackedXyzPly(path).has_value(), c.direct);
    ExpectSameAsGeneral(path, c.bytes);
  }
}

TEST(ReadPackedXyzPly, KeepsTheGeneralReadersLimitsAndMissingFileError) {
  TempDir dir;
  const std::string path = dir.File("scan.ply");
  const std::string bytes = Header("", 1000) + "end_header\n" + Rows(1000, 4);
  WriteBytes(path, bytes);
  CloudReadLimits small;
  small.max_points = 999;
  EXPECT_FALSE(ReadPackedXyzPly(path, small).has_value());
  const auto refused = ReadPointCloud(path, small);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kResourceExhausted) << refused.status();
  ExpectSameAsGeneral(path, bytes, small);
  EXPECT_FALSE(ReadPackedXyzPly(dir.File("missing.ply")).has_value());
  EXPECT_FALSE(ReadPointCloud(dir.File("missing.ply")).ok());
  EXPECT_FALSE(ReadPackedXyzPly(dir.path()).has_value()) << "a directory";
}

// Headers whose end meets the 64 KiB the direct read parses first: the
// newline after end_header just inside, just outside, and a "\r\n" split
// across the edge. The general reader refuses a header past 64 KiB; the
// direct one may neither accept such a header nor shift the rows.
TEST(ReadPackedXyzPly, AgreesAtTheEdgeOfItsFirstRead) {
  TempDir dir;
  const std::size_t n = 100, head = 64 * 1024;
  const std::string rows = Rows(n, 6);
  for (const char* end_line : {"end_header\n", "end_header\r\n"}) {
    const std::string end = end_line;
    for (int shift = -3; shift <= 3; ++shift) {
      std::string header = Header("", n);
      const std::size_t target = head + shift;  // where the end line's last byte ends
      std::string pad = "comment ";
      while (header.size() + pad.size() + 1 + end.size() < target) pad += 'p';
      if (header.size() + pad.size() + 1 + end.size() != target) continue;
      header += pad + "\n" + end;
      const std::string bytes = header + rows;
      const std::string path = dir.File("edge.ply");
      WriteBytes(path, bytes);
      SCOPED_TRACE(std::to_string(shift) + (end.size() == 12 ? " crlf" : " lf"));
      ExpectSameAsGeneral(path, bytes);
    }
  }
}

// Every single-byte change of the header of a file in our writer's layout:
// the direct read and the general one still agree.
TEST(ReadPackedXyzPly, AgreesWithTheGeneralReaderOnMutatedHeaders) {
  TempDir dir;
  const std::size_t n = 64;
  const std::string header = Header("obj_info num_cols 64\nobj_info num_rows 1\n", n) +
                             "element face 0\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string rows = Rows(n, 5);
  std::mt19937 rng(9);
  const char replacements[] = {'0', '1', '9', ' ', '\n', 'x', 'e', '\0', '-'};
  const std::string path = dir.File("scan.ply");
  for (std::size_t at = 0; at < header.size(); ++at) {
    std::string bytes = header + rows;
    bytes[at] = replacements[rng() % sizeof replacements];
    WriteBytes(path, bytes);
    SCOPED_TRACE(at);
    ExpectSameAsGeneral(path, bytes);
  }
}

}  // namespace
}  // namespace surfinspect
