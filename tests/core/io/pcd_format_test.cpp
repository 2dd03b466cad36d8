// Tests core/io/pcd_format.cpp (the header) and core/io/pcd_data.cpp (the
// data section, all three encodings) through ParsePcd.
#include "core/io/pcd_format.h"

#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "core/io/io_point_cloud.h"
#include "tests/support/temp_dir.h"

namespace surfinspect {
namespace {

const std::string kHead = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";

void ExpectRefused(const std::string& bytes, const char* message_part,
                   absl::StatusCode code = absl::StatusCode::kInvalidArgument) {
  auto c = ParsePcd(bytes, {}, "scan.pcd");
  ASSERT_FALSE(c.ok()) << message_part;
  EXPECT_EQ(c.status().code(), code) << c.status();
  EXPECT_NE(c.status().message().find(message_part), std::string::npos) << c.status();
  EXPECT_EQ(c.status().message().rfind("scan.pcd: ", 0), 0u) << "names the file";
}

TEST(ParsePcd, RefusesEveryMalformedHeaderWithItsReason) {
  const std::string dims = "WIDTH 1\nHEIGHT 1\nPOINTS 1\n";
  ExpectRefused("surfinspect\n" + kHead + dims + "DATA ascii\n1 2 3\n",
                "unknown key 'surfinspect'");
  ExpectRefused(kHead + "WIDTH 1\n" + dims + "DATA ascii\n1 2 3\n", "repeated key WIDTH");
  ExpectRefused("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 \x07~ 1\n" + dims +
                    kHead + dims + "DATA ascii\n1 2 3\n",
                "line 9: repeated key VERSION");
  ExpectRefused("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 \x07~ 1\n" + dims +
                    "DATA ascii\n1 2 3\n",
                "bad COUNT for field y");
  ExpectRefused("VERSION 0.7\nFIELDS x y z\nSIZE 4 4\nTYPE F F F\n" + dims + "DATA ascii\n1 2 3\n",
                "FIELDS, SIZE, TYPE and COUNT disagree in length");
  ExpectRefused(
      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 2\nTYPE F F F\n" + dims + "DATA ascii\n1 2 3\n",
      "bad TYPE for field z");
  ExpectRefused(
      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F U\n" + dims + "DATA ascii\n1 2 3\n",
      "field z must be float32 or float64");
  ExpectRefused(
      "VERSION 0.7\nFIELDS x y x z\nSIZE 4 4 4 4\nTYPE F F F F\n" + dims + "DATA ascii\n1 2 3 4\n",
      "repeated field x");
  ExpectRefused(kHead + "WIDTH 1x\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3\n", "not a number");
  ExpectRefused(kHead + "WIDTH 4294967296\nHEIGHT 4294967296\nPOINTS 0\nDATA binary\n",
                "no points");
  ExpectRefused(kHead + "WIDTH 4294967296\nHEIGHT 1\nPOINTS 4294967296\nDATA binary\n",
                "does not equal POINTS");
  ExpectRefused(kHead + "WIDTH 2\nHEIGHT 2\nPOINTS 3\nDATA binary\n", "does not equal POINTS");
  ExpectRefused(kHead + "WIDTH 4000000000\nHEIGHT 1\nPOINTS 4000000000\nDATA binary\n",
                "exceed the limit", absl::StatusCode::kResourceExhausted);
  ExpectRefused(kHead + dims + "DATA zip\n", "unknown DATA encoding 'zip'");
  ExpectRefused(kHead + dims, "no 'DATA' line");
  ExpectRefused(kHead + "WIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3\n", "lacks HEIGHT");
  ExpectRefused(kHead + "VIEWPOINT 0 0 0 1 0 0\n" + dims + "DATA ascii\n1 2 3\n", "VIEWPOINT");
  ExpectRefused("# c\n" + std::string(70000, '#') + "\n", "header too long");
}

TEST(ParsePcd, RefusesShortOrBadDataSections) {
  ExpectRefused(kHead + "WIDTH 4\nHEIGHT 1\nPOINTS 4\nDATA binary\n" + std::string(47, '\0'),
                "truncated: 4 points need 48 data bytes, file has 47");
  ExpectRefused(kHead + "WIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA ascii\n1 2 3\n\n4 5 6\n",
                "3 points declared, 2 data lines found");
  ExpectRefused(kHead + "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2\n", "has 2 values");
  ExpectRefused(kHead + "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3x\n", "bad number '3x'");
  ExpectRefused(kHead + "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 inf 3\n", "infinite");
  const std::string comp = kHead + "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA binary_compressed\n";
  ExpectRefused(comp + "abc", "compressed block sizes missing");
  ExpectRefused(comp + std::string("\x04\0\0\0\x0d\0\0\0", 8) + "abcd",
                "uncompressed size disagrees");
  ExpectRefused(comp + std::string("\x40\0\0\0\x0c\0\0\0", 8) + "abc",
                "compressed data shorter than declared");
  // A 4-byte literal, then a 264-byte back reference: past the 12 declared bytes.
  ExpectRefused(comp + std::string("\x08\0\0\0\x0c\0\0\0", 8) +
                    std::string("\x03"
                                "abcd\xe0\xff\x03",
                                8),
                "LZF block decodes past its declared size");
}

// One writer's output per encoding, read back bit for bit by the byte parser.
TEST(ParsePcd, ReadsWhatPclWritesInEveryEncodingBitExact) {
  testing::TempDir dir;
  PointCloud grid = PointCloud::Organized(7, 5);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-500.f, 500.f);
  for (std::size_t i = 0; i < grid.size(); ++i)
    if (i % 4 != 1) grid.points[i] = {u(rng), u(rng), u(rng)};
  for (PcdEncoding enc :
       {PcdEncoding::kAscii, PcdEncoding::kBinary, PcdEncoding::kBinaryCompressed}) {
    const std::string path = dir.File("g.pcd");
    ASSERT_TRUE(WritePointCloud(path, grid, enc).ok());
    auto back = ParsePcd(testing::ReadBytes(path));
    ASSERT_TRUE(back.ok()) << back.status();
    ASSERT_EQ(back->width, 7u);
    ASSERT_EQ(back->height, 5u);
    for (std::size_t i = 0; i < grid.size(); ++i) {
      ASSERT_EQ(PointCloud::IsValid(grid.points[i]), PointCloud::IsValid(back->points[i])) << i;
      if (PointCloud::IsValid(grid.points[i])) {
        ASSERT_EQ(0, std::memcmp(grid.points[i].data(), back->points[i].data(), 12)) << i;
      }
    }
  }
}

TEST(ParsePcd, SkipsOtherFieldsAndPaddingAndConvertsDoubles) {
  std::string bytes =
      "# comment\nVERSION .7\nFIELDS _ x y z rgb\nSIZE 1 8 8 8 4\nTYPE U F F F U\nCOUNT 3 1 1 1 1\n"
      "WIDTH 1\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\nDATA binary\n";
  const double xyz[3] = {0.1, -2.5, 1e10};
  bytes += std::string(3, '\x7f');
  bytes.append(reinterpret_cast<const char*>(xyz), 24);
  bytes += std::string(4, '\x01');
  auto c = ParsePcd(bytes);
  ASSERT_TRUE(c.ok()) << c.status();
  EXPECT_EQ(c->points[0], Eigen::Vector3f(static_cast<float>(0.1), -2.5f, 1e10f));
}

// VIEWPOINT is kept in the header in the file's order (tx ty tz, then qw qx
// qy qz) and never applied to the points.
TEST(ParsePcdHeader, KeepsTheViewpointWithoutApplyingIt) {
  const std::string body = "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3\n4 5 6\n";
  const std::string bytes = kHead + "VIEWPOINT 12.5 -3 0.25 0.5 -0.5 0.5 0.5\n" + body;
  auto h = ParsePcdHeader(bytes, {}, "v.pcd");
  ASSERT_TRUE(h.ok()) << h.status();
  ASSERT_TRUE(h->viewpoint.has_value());
  const PcdViewpoint& v = *h->viewpoint;
  EXPECT_EQ(v.tx, 12.5);
  EXPECT_EQ(v.ty, -3);
  EXPECT_EQ(v.tz, 0.25);
  EXPECT_EQ(v.qw, 0.5);
  EXPECT_EQ(v.qx, -0.5);
  EXPECT_EQ(v.qy, 0.5);
  EXPECT_EQ(v.qz, 0.5);
  auto c = ParsePcd(bytes);
  ASSERT_TRUE(c.ok()) << c.status();
  EXPECT_EQ(c->points[0], Eigen::Vector3f(1, 2, 3));
  EXPECT_EQ(c->points[1], Eigen::Vector3f(4, 5, 6));
  auto none = ParsePcdHeader(kHead + body, {}, "n.pcd");
  ASSERT_TRUE(none.ok()) << none.status();
  EXPECT_FALSE(none->viewpoint.has_value());
}

// ReadPcdHeader reads the file's first bytes only, to the same header, or
// the same refusal when the header runs past 64 KiB (here a DATA line that
// the first read cuts to "DATA binary").
TEST(ReadPcdHeader, ReadsTheHeadOfTheFileAsParsePcdHeaderReadsTheWhole) {
  testing::TempDir dir;
  const std::string bytes = kHead + "WIDTH 1\nHEIGHT 1\nVIEWPOINT 1 2 3 0 0 0 1\nPOINTS 1\n" +
                            "DATA binary\n" + std::string(12, '\0');
  testing::WriteBytes(dir.File("v.pcd"), bytes);
  auto h = ReadPcdHeader(dir.File("v.pcd"));
  ASSERT_TRUE(h.ok()) << h.status();
  ASSERT_TRUE(h->viewpoint.has_value());
  EXPECT_EQ(h->viewpoint->tz, 3);
  EXPECT_EQ(h->viewpoint->qz, 1);
  EXPECT_EQ(h->data_offset, bytes.size() - 12);
  // The first read, 64 KiB and one byte, ends just after "DATA binary".
  const std::string dims = "\nWIDTH 1\nHEIGHT 1\nPOINTS 1\n";
  const std::string pad(64 * 1024 + 1 - kHead.size() - 1 - dims.size() - 11, 'p');
  const std::string cut =
      kHead + "#" + pad + dims + "DATA binary_compressed\n" + std::string(100, '\0');
  ASSERT_EQ(cut.substr(64 * 1024 - 10, 11), "DATA binary");
  testing::WriteBytes(dir.File("cut.pcd"), cut);
  auto refused = ReadPcdHeader(dir.File("cut.pcd"));
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status(), ParsePcd(cut, {}, dir.File("cut.pcd")).status());
  EXPECT_EQ(ReadPcdHeader(dir.File("missing.pcd")).status().code(), absl::StatusCode::kNotFound);
}

}  // namespace
}  // namespace surfinspect
