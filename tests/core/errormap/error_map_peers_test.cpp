// The error-map PLY of core/report/error_map_output.cpp as its peers load
// it: Debian's CloudCompare in command-line mode (a real run), and the
// property rules of MeshLab's PLY importer (vcglib wrap/io_trimesh/
// import_ply.h: vertex "x" "y" "z" float, "quality" float, "red" "green"
// "blue" uchar; other properties are skipped by their size).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "core/io/io_point_cloud.h"
#include "core/report/error_map_output.h"
#include "tests/support/temp_dir.h"

namespace surfinspect {
namespace {

using testing::TempDir;

// 30 points on a slanted line, every fourth unmatched (NaN), one invalid
// point (not written), deviations with all 24 mantissa bits in use.
struct Fixture {
  PointCloud cloud;
  ErrorMapResult result;
  std::vector<float> written;  // deviations of the valid points, in order
  std::vector<Eigen::Vector3f> written_xyz;
};

Fixture MakeFixture() {
  Fixture f;
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i < 30; ++i) {
    pts.emplace_back(1.5f * i, 0.25f * i - 3, 100.0f + i);
    const float d = i % 4 == 3 ? NAN : (i - 15) * 0.0312345f + 1e-7f * i;
    f.result.deviation_mm.push_back(d);
  }
  pts[10] = Eigen::Vector3f(NAN, NAN, NAN);
  f.cloud = PointCloud::Unorganized(pts);
  f.result.tolerance_mm = 0.1;
  f.result.color_range_mm = 0.5;
  for (int i = 0; i < 30; ++i)
    if (i != 10) {
      f.written.push_back(f.result.deviation_mm[i]);
      f.written_xyz.push_back(pts[i]);
    }
  return f;
}

bool SameDeviation(double got, float want) {
  return std::isnan(want) ? std::isnan(got) : std::abs(got - want) <= 1e-9;
}

TEST(ErrorMapPeers, CloudCompareLoadsScalarDeviationWithNaN) {
  if (std::system("command -v CloudCompare >/dev/null 2>&1") != 0) {
    std::fprintf(stderr,
                 "\n*** CloudCompare is NOT INSTALLED: the PLY is NOT checked against it ***\n\n");
    GTEST_SKIP() << "CloudCompare not installed (Debian package cloudcompare)";
  }
  const Fixture f = MakeFixture();
  TempDir dir;
  ASSERT_TRUE(WriteErrorMapPly(dir.File("in.ply"), f.cloud, f.result, "part").ok());
  const std::string cmd = "cd '" + dir.path() +
                          "' && QT_QPA_PLATFORM=offscreen CloudCompare -SILENT -AUTO_SAVE OFF "
                          "-O in.ply -C_EXPORT_FMT ASC -ADD_HEADER -SAVE_CLOUDS FILE out.asc "
                          ">cc.log 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << testing::ReadBytes(dir.File("cc.log"));
  std::ifstream in(dir.File("out.asc"));
  std::string header;
  ASSERT_TRUE(std::getline(in, header)) << testing::ReadBytes(dir.File("cc.log"));
  // "quality" is not a scalar field for CloudCompare; the colour is kept.
  EXPECT_EQ(header, "//X Y Z R G B deviation");
  std::size_t k = 0;
  for (std::string line; std::getline(in, line); ++k) {
    ASSERT_LT(k, f.written.size());
    std::istringstream row(line);
    double x, y, z, d;
    int r, g, b;
    std::string dev;
    ASSERT_TRUE(row >> x >> y >> z >> r >> g >> b >> dev) << line;
    d = dev == "nan" || dev == "-nan" ? NAN : std::stod(dev);
    EXPECT_TRUE(SameDeviation(d, f.written[k])) << k << ": " << dev << " vs " << f.written[k];
    EXPECT_NEAR(x, f.written_xyz[k].x(), 1e-5);
    EXPECT_NEAR(z, f.written_xyz[k].z(), 1e-5);
    const Rgb c = DeviationColor(f.written[k], 0.1, 0.5);
    EXPECT_EQ(r, c.r);
    EXPECT_EQ(b, c.b);
  }
  EXPECT_EQ(k, f.written.size());
}

// The header as vcglib's PlyFile reads it: format, the vertex element, and
// each property's type and byte offset in a binary record.
struct PlyLayout {
  std::string format;
  std::size_t vertices = 0, record = 0, data_offset = 0;
  std::map<std::string, std::pair<std::string, std::size_t>> props;  // name -> type, offset
};

PlyLayout ReadLayout(const std::string& bytes) {
  static const std::map<std::string, std::size_t> kSize = {
      {"char", 1}, {"uchar", 1}, {"short", 2},  {"ushort", 2},  {"int", 4},
      {"uint", 4}, {"float", 4}, {"double", 8}, {"float32", 4}, {"uint8", 1}};
  PlyLayout l;
  const std::size_t end = bytes.find("end_header\n");
  if (end == std::string::npos) return l;
  l.data_offset = end + 11;
  std::istringstream lines(bytes.substr(0, end));
  for (std::string line; std::getline(lines, line);) {
    std::istringstream w(line);
    std::string key, a, b;
    w >> key >> a >> b;
    if (key == "format") l.format = a + " " + b;
    if (key == "element" && a == "vertex") l.vertices = std::stoul(b);
    if (key == "property" && kSize.count(a)) {
      l.props[b] = {a, l.record};
      l.record += kSize.at(a);
    }
  }
  return l;
}

TEST(ErrorMapPeers, MeshLabReadsQualityAsVcglibDoes) {
  const Fixture f = MakeFixture();
  TempDir dir;
  ASSERT_TRUE(WriteErrorMapPly(dir.File("m.ply"), f.cloud, f.result, "part").ok());
  const std::string bytes = testing::ReadBytes(dir.File("m.ply"));
  const PlyLayout l = ReadLayout(bytes);
  EXPECT_EQ(l.format, "binary_little_endian 1.0");
  ASSERT_EQ(l.vertices, f.written.size());
  // vcglib's descriptors: on-file types must be exactly these.
  for (const char* p : {"x", "y", "z", "quality"}) {
    ASSERT_TRUE(l.props.count(p)) << p;
    EXPECT_EQ(l.props.at(p).first, "float") << p;
  }
  for (const char* p : {"red", "green", "blue"}) {
    ASSERT_TRUE(l.props.count(p)) << p;
    EXPECT_EQ(l.props.at(p).first, "uchar") << p;
  }
  ASSERT_EQ(bytes.size(), l.data_offset + l.vertices * l.record) << "no trailing bytes";
  for (std::size_t k = 0; k < l.vertices; ++k) {
    const char* rec = bytes.data() + l.data_offset + k * l.record;
    float q, x;
    std::memcpy(&q, rec + l.props.at("quality").second, 4);
    std::memcpy(&x, rec + l.props.at("x").second, 4);
    EXPECT_TRUE(SameDeviation(q, f.written[k])) << k;
    if (!std::isnan(q)) {
      EXPECT_EQ(q, f.written[k]) << "bit-exact";
    }
    EXPECT_EQ(x, f.written_xyz[k].x());
    const Rgb c = DeviationColor(f.written[k], 0.1, 0.5);
    EXPECT_EQ(static_cast<uint8_t>(rec[l.props.at("green").second]), c.g);
  }
}

// Our own cloud reader takes x y z and skips the other properties.
TEST(ErrorMapPeers, OwnReaderReadsTheErrorMapPlyAsACloud) {
  const Fixture f = MakeFixture();
  TempDir dir;
  ASSERT_TRUE(WriteErrorMapPly(dir.File("e.ply"), f.cloud, f.result, "part").ok());
  auto cloud = ReadPointCloud(dir.File("e.ply"));
  ASSERT_TRUE(cloud.ok()) << cloud.status();
  ASSERT_EQ(cloud->size(), f.written_xyz.size());
  for (std::size_t k = 0; k < cloud->size(); ++k) EXPECT_EQ(cloud->points[k], f.written_xyz[k]);
}

}  // namespace
}  // namespace surfinspect
