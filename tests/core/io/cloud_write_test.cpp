#include "core/io/cloud_write.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/io/lzf.h"
#include "core/io/pcd_format.h"
#include "core/io/ply_cloud.h"

namespace surfinspect {
namespace {

// The 16 x 8 grid that tests/core/io/golden/pcl113_* were written from, by
// PCL 1.13's PCDWriter (writeASCII with precision 9, writeBinary) and
// PLYWriter (writeBinary, valid points only, no camera): every 7th pixel
// from the 4th is NaN.
PointCloud GoldenGrid() {
  PointCloud c = PointCloud::Organized(16, 8);
  for (uint32_t i = 0; i < c.size(); ++i)
    if (i % 7 != 3)
      c.points[i] = {0.37f * static_cast<float>(i) - 5.f,
                     -1.25f * static_cast<float>(i / 16) + 1e-3f * static_cast<float>(i),
                     400.f + std::sin(0.1f * static_cast<float>(i))};
  return c;
}

std::string Golden(const std::string& name) {
  std::ifstream in(std::string(SURFINSPECT_SOURCE_DIR) + "/tests/core/io/golden/" + name,
                   std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(CloudWrite, PcdAsciiIsPclsBytes) {
  const std::string gold = Golden("pcl113_grid_ascii.pcd");
  ASSERT_FALSE(gold.empty());
  EXPECT_EQ(EncodePcd(GoldenGrid(), PcdEncoding::kAscii), gold);
}

TEST(CloudWrite, PcdBinaryIsPclsBytesPaddingIncluded) {
  const std::string gold = Golden("pcl113_grid_binary.pcd");
  ASSERT_EQ(gold.size(), 4096u + 128 * 12);  // the header's page, then the data
  EXPECT_EQ(EncodePcd(GoldenGrid(), PcdEncoding::kBinary), gold);
}

TEST(CloudWrite, PlyBinaryIsPclsBytes) {
  const std::string gold = Golden("pcl113_grid_valid_binary.ply");
  ASSERT_FALSE(gold.empty());
  EXPECT_EQ(EncodePly(GoldenGrid(), /*binary=*/true), gold);
}

TEST(CloudWrite, PcdBinaryCompressedHoldsTheThreePlanesInLzf) {
  const PointCloud grid = GoldenGrid();
  const std::string file = EncodePcd(grid, PcdEncoding::kBinaryCompressed);
  const std::string marker = "DATA binary_compressed\n";
  const std::size_t at = file.find(marker);
  ASSERT_NE(at, std::string::npos);
  const std::size_t body = at + marker.size();
  uint32_t packed = 0, planes = 0;
  std::memcpy(&packed, &file[body], 4);
  std::memcpy(&planes, &file[body + 4], 4);
  ASSERT_EQ(planes, grid.size() * 12);
  ASSERT_EQ(file.size(), body + 8 + packed);
  auto decoded = LzfDecompress(std::string_view(file).substr(body + 8), planes);
  ASSERT_TRUE(decoded.ok()) << decoded.status();
  for (std::size_t i = 0; i < grid.size(); ++i)
    for (int a = 0; a < 3; ++a)
      ASSERT_EQ(0, std::memcmp(&(*decoded)[(a * grid.size() + i) * 4], &grid.points[i][a], 4))
          << "pixel " << i << " axis " << a;
}

TEST(CloudWrite, AsciiNaNIsWrittenAsPclWritesItWhateverItsSign) {
  PointCloud c = PointCloud::Organized(2, 2);
  c.points[0] = {-NAN, -NAN, -NAN};
  c.points[1] = {-0.f, 1e-45f, 123456789.f};  // as PCL printed them
  const std::string file = EncodePcd(c, PcdEncoding::kAscii);
  EXPECT_NE(file.find("DATA ascii\nnan nan nan\n-0 1.40129846e-45 123456792\nnan nan nan\n"),
            std::string::npos)
      << file;
}

// The unit comment is one line more than PCL's bytes, in each encoding, and
// our readers (as PCL's) read the same points through it.
TEST(CloudWrite, TheUnitCommentIsOneLineMoreThanPclsBytesAndReadsTheSame) {
  const PointCloud grid = GoldenGrid();
  std::string gold = Golden("pcl113_grid_ascii.pcd");
  gold.insert(gold.find('\n') + 1, "# units: mm\n");
  EXPECT_EQ(EncodePcd(grid, PcdEncoding::kAscii, "mm"), gold);
  const std::string ply = Golden("pcl113_grid_valid_binary.ply");
  const std::string marker = "comment PCL generated\n";
  std::string ply_gold = ply;
  ply_gold.insert(ply.find(marker) + marker.size(), "comment units: m\n");
  EXPECT_EQ(EncodePly(grid, true, "m"), ply_gold);
  for (PcdEncoding e :
       {PcdEncoding::kAscii, PcdEncoding::kBinary, PcdEncoding::kBinaryCompressed}) {
    const absl::StatusOr<PointCloud> back = ParsePcd(EncodePcd(grid, e, "in"));
    ASSERT_TRUE(back.ok()) << back.status();
    ASSERT_EQ(back->size(), grid.size());
    EXPECT_EQ(0, std::memcmp(back->points.data(), grid.points.data(), grid.size() * 12));
  }
  const absl::StatusOr<PointCloud> ascii_ply = ParsePlyCloud(EncodePly(grid, false, "mm"));
  ASSERT_TRUE(ascii_ply.ok()) << ascii_ply.status();
  EXPECT_EQ(ascii_ply->size(), grid.CountValid());
}

}  // namespace
}  // namespace surfinspect
