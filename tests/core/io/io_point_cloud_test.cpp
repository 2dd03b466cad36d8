#include "core/io/io_point_cloud.h"

#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "tests/support/temp_dir.h"

namespace surfinspect {
namespace {

using testing::TempDir;
using testing::WriteBytes;

// A 1024x768 grid with a wavy surface and ~10% NaN pixels.
PointCloud MakeGrid(uint32_t w = 1024, uint32_t h = 768) {
  PointCloud c = PointCloud::Organized(w, h);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (uint32_t r = 0; r < h; ++r)
    for (uint32_t col = 0; col < w; ++col) {
      if (u(rng) < 0.1f) continue;
      c.points[r * w + col] = {0.137f * col - 70.f, 0.141f * r - 54.f,
                               400.f + 3.f * std::sin(0.01f * col) + u(rng) * 1e-3f};
    }
  return c;
}

// Bits equal for valid points; both invalid otherwise.
void ExpectSameGrid(const PointCloud& a, const PointCloud& b) {
  ASSERT_EQ(a.width, b.width);
  ASSERT_EQ(a.height, b.height);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const bool va = PointCloud::IsValid(a.points[i]);
    ASSERT_EQ(va, PointCloud::IsValid(b.points[i])) << "pixel " << i;
    if (va) {
      ASSERT_EQ(0, std::memcmp(a.points[i].data(), b.points[i].data(), 12)) << "pixel " << i;
    }
  }
}

class PcdRoundTrip : public ::testing::TestWithParam<PcdEncoding> {};

TEST_P(PcdRoundTrip, OrganizedGridWithNaNIsBitExact) {
  TempDir dir;
  const PointCloud grid = MakeGrid();
  ASSERT_TRUE(WritePointCloud(dir.File("g.pcd"), grid, GetParam()).ok());
  auto back = ReadPointCloud(dir.File("g.pcd"));
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_TRUE(back->organized());
  ExpectSameGrid(grid, *back);
}

INSTANTIATE_TEST_SUITE_P(AllEncodings, PcdRoundTrip,
                         ::testing::Values(PcdEncoding::kAscii, PcdEncoding::kBinary,
                                           PcdEncoding::kBinaryCompressed));

TEST(PlyRoundTrip, BinaryAndAsciiKeepValidPoints) {
  TempDir dir;
  const PointCloud grid = MakeGrid(64, 48);
  for (bool binary : {true, false}) {
    const std::string path = dir.File(binary ? "b.ply" : "a.ply");
    ASSERT_TRUE(WritePointCloud(path, grid, PcdEncoding::kBinary, binary).ok());
    auto back = ReadPointCloud(path);
    ASSERT_TRUE(back.ok()) << back.status();
    EXPECT_FALSE(back->organized());
    std::vector<Eigen::Vector3f> expected;
    grid.ForEachValid([&](std::size_t, const Eigen::Vector3f& p) { expected.push_back(p); });
    ASSERT_EQ(back->size(), expected.size());
    for (std::size_t i = 0; i < expected.size(); ++i) {
      ASSERT_EQ(0, std::memcmp(expected[i].data(), back->points[i].data(), 12)) << i;
    }
  }
}

std::string BigEndianFloat(float f) {
  uint32_t u;
  std::memcpy(&u, &f, 4);
  std::string s(4, '\0');
  for (int i = 0; i < 4; ++i) s[i] = static_cast<char>((u >> (24 - 8 * i)) & 0xff);
  return s;
}

TEST(PlyRead, BigEndianBinary) {
  TempDir dir;
  std::string body;
  for (float v : {1.5f, -2.25f, 400.125f, 3.f, 4.f, 5.f}) body += BigEndianFloat(v);
  WriteBytes(dir.File("be.ply"),
             "ply\nformat binary_big_endian 1.0\nelement vertex 2\nproperty float x\n"
             "property float y\nproperty float z\nend_header\n" +
                 body);
  auto c = ReadPointCloud(dir.File("be.ply"));
  ASSERT_TRUE(c.ok()) << c.status();
  ASSERT_EQ(c->size(), 2u);
  EXPECT_EQ(c->points[0], Eigen::Vector3f(1.5f, -2.25f, 400.125f));
  EXPECT_EQ(c->points[1], Eigen::Vector3f(3.f, 4.f, 5.f));
}

TEST(PcdRead, DoubleFieldsAndExtraFields) {
  TempDir dir;
  WriteBytes(dir.File("d.pcd"),
             "VERSION 0.7\nFIELDS x y z intensity\nSIZE 8 8 8 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
             "WIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n"
             "1.25 2.5 3.75 9\n-1 -2 -3 9\n");
  auto c = ReadPointCloud(dir.File("d.pcd"));
  ASSERT_TRUE(c.ok()) << c.status();
  ASSERT_EQ(c->size(), 2u);
  EXPECT_EQ(c->points[0], Eigen::Vector3f(1.25f, 2.5f, 3.75f));
  EXPECT_EQ(c->points[1], Eigen::Vector3f(-1.f, -2.f, -3.f));
}

// ---- malformed files: each must give a clear error, never a crash -------

struct Malformed {
  const char* name;
  const char* file;
  std::string bytes;
  absl::StatusCode code;
  const char* message_part;
};

const std::string kPcdHead = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";

std::vector<Malformed> MalformedClouds() {
  return {
      {"empty_pcd", "e.pcd", "", absl::StatusCode::kInvalidArgument, "empty"},
      {"no_data_line", "n.pcd", kPcdHead + "WIDTH 1\nHEIGHT 1\nPOINTS 1\n",
       absl::StatusCode::kInvalidArgument, "truncated header"},
      {"truncated_binary", "t.pcd",
       kPcdHead + "WIDTH 4\nHEIGHT 1\nPOINTS 4\nDATA binary\n" + std::string(20, '\0'),
       absl::StatusCode::kInvalidArgument, "truncated"},
      {"count_mismatch", "m.pcd",
       kPcdHead + "WIDTH 4\nHEIGHT 2\nPOINTS 5\nDATA binary\n" + std::string(120, '\0'),
       absl::StatusCode::kInvalidArgument, "does not equal POINTS"},
      {"no_z_field", "z.pcd",
       "VERSION 0.7\nFIELDS x y\nSIZE 4 4\nTYPE F F\nCOUNT 1 1\nWIDTH 1\nHEIGHT 1\nPOINTS 1\n"
       "DATA ascii\n1 2\n",
       absl::StatusCode::kInvalidArgument, "no x, y and z"},
      {"huge_count", "h.pcd",
       kPcdHead + "WIDTH 4000000000\nHEIGHT 1\nPOINTS 4000000000\nDATA binary\n",
       absl::StatusCode::kResourceExhausted, "limit"},
      {"ascii_short", "a.pcd", kPcdHead + "WIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA ascii\n1 2 3\n4 5 6\n",
       absl::StatusCode::kInvalidArgument, "2 data lines"},
      {"compressed_short", "c.pcd",
       kPcdHead + "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA binary_compressed\n" +
           std::string("\x40\x00\x00\x00\x18\x00\x00\x00", 8) + "abc",
       absl::StatusCode::kInvalidArgument, "compressed"},
      {"unknown_encoding", "u.pcd", kPcdHead + "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA zip\n",
       absl::StatusCode::kInvalidArgument, "unknown DATA"},
      {"bad_size", "s.pcd",
       "VERSION 0.7\nFIELDS x y z\nSIZE 4 3 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1\nHEIGHT 1\n"
       "POINTS 1\nDATA ascii\n1 2 3\n",
       absl::StatusCode::kInvalidArgument, "bad SIZE"},
      {"ply_truncated", "t.ply",
       "ply\nformat binary_little_endian 1.0\nelement vertex 10\nproperty float x\n"
       "property float y\nproperty float z\nend_header\n" +
           std::string(12, '\0'),
       absl::StatusCode::kInvalidArgument, "truncated"},
      {"ply_no_magic", "m.ply", "plx\nformat ascii 1.0\nend_header\n",
       absl::StatusCode::kInvalidArgument, "magic"},
      {"ply_bad_type", "b.ply",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n1\n",
       absl::StatusCode::kInvalidArgument, "unknown type"},
      {"ply_huge", "h.ply",
       "ply\nformat binary_little_endian 1.0\nelement vertex 999999999999\nproperty float x\n"
       "property float y\nproperty float z\nend_header\n",
       absl::StatusCode::kResourceExhausted, "limit"},
      {"ply_no_header_end", "e.ply", "ply\nformat ascii 1.0\nelement vertex 1\n",
       absl::StatusCode::kInvalidArgument, "end_header"},
      {"ply_inf_point", "i.ply",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
       "property float z\nend_header\n1 inf 3\n",
       absl::StatusCode::kInvalidArgument, "infinite"},
      {"wrong_extension", "x.xyz", "1 2 3\n", absl::StatusCode::kInvalidArgument,
       "unknown cloud format"},
  };
}

class MalformedCloud : public ::testing::TestWithParam<Malformed> {};

TEST_P(MalformedCloud, GivesClearError) {
  TempDir dir;
  const Malformed& m = GetParam();
  const std::string path = dir.File(m.file);
  WriteBytes(path, m.bytes);
  auto c = ReadPointCloud(path);
  ASSERT_FALSE(c.ok()) << m.name;
  EXPECT_EQ(c.status().code(), m.code) << c.status();
  EXPECT_NE(c.status().message().find(m.message_part), std::string::npos) << c.status();
  EXPECT_NE(c.status().message().find(path), std::string::npos) << "names the file";
}

INSTANTIATE_TEST_SUITE_P(Files, MalformedCloud, ::testing::ValuesIn(MalformedClouds()),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(ReadPointCloud, MissingFileIsNotFound) {
  auto c = ReadPointCloud("/nonexistent/dir/scan.pcd");
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.status().code(), absl::StatusCode::kNotFound);
}

TEST(WritePointCloud, RejectsInconsistentGridAndLeavesNoFile) {
  TempDir dir;
  PointCloud bad = PointCloud::Organized(4, 4);
  bad.points.pop_back();
  EXPECT_FALSE(WritePointCloud(dir.File("bad.pcd"), bad).ok());
  EXPECT_TRUE(testing::ReadBytes(dir.File("bad.pcd")).empty());
}

}  // namespace
}  // namespace surfinspect
