// core/report/error_map_output.cpp (the PLY and the CSV), the error map's
// part of report.json (core/pipeline/inspection_report.cpp) and its PNG
// (core/report/error_map_png.cpp), on a small organized scan of a plane.
#include "core/report/error_map_output.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "core/pipeline/inspection_report.h"
#include "core/report/error_map_png.h"
#include "tests/support/temp_dir.h"
#include "tests/support/test_meshes.h"

namespace surfinspect {
namespace {

using Eigen::Vector3f;
using testing::TempDir;

struct ScanFixture {
  std::unique_ptr<MeshIndex> index;
  PointCloud cloud;
  ErrorMapResult result;
};

ScanFixture SmallOrganizedScan() {
  ScanFixture f;
  f.index = testing::IndexOf(testing::FlatSquare());
  f.cloud = PointCloud::Organized(40, 30);
  for (uint32_t r = 0; r < 30; ++r)
    for (uint32_t c = 0; c < 40; ++c) {
      if ((r * 40 + c) % 17 == 0) continue;  // NaN holes
      const float z = c < 10   ? 0.5f
                      : c < 20 ? -0.5f
                      : c < 30 ? 0.01f
                               : 20.f;  // last block unmatched
      f.cloud.points[r * 40 + c] = Vector3f(10 + 2 * c, 10 + 2 * r, z);
    }
  ErrorMapSettings s;
  s.split_components = true;
  f.result = *ComputeErrorMap(*f.index, f.cloud, Eigen::Isometry3d::Identity(), s);
  return f;
}

TEST(ErrorMapOutput, PlyHoldsValidPointsDeviationAndColour) {
  const ScanFixture f = SmallOrganizedScan();
  TempDir dir;
  const std::string path = dir.File("map.ply");
  ASSERT_TRUE(WriteErrorMapPly(path, f.cloud, f.result, "part").ok());
  std::ifstream in(path, std::ios::binary);
  std::string line, header;
  std::size_t vertices = 0;
  while (std::getline(in, line) && line != "end_header") {
    header += line + "\n";
    if (line.rfind("element vertex ", 0) == 0) vertices = std::stoul(line.substr(15));
  }
  EXPECT_NE(header.find("format binary_little_endian 1.0"), std::string::npos);
  EXPECT_NE(header.find("property float scalar_deviation\nproperty float quality\n"
                        "property uchar red\nproperty uchar green\nproperty uchar blue"),
            std::string::npos);
  EXPECT_NE(header.find("comment frame: part"), std::string::npos);
  ASSERT_EQ(vertices, f.cloud.CountValid());
  std::size_t k = 0;
  for (std::size_t i = 0; i < f.cloud.size(); ++i) {
    if (!PointCloud::IsValid(f.cloud.points[i])) continue;
    char rec[23];
    ASSERT_TRUE(in.read(rec, 23)) << k;
    float xyzd[5];
    std::memcpy(xyzd, rec, 20);
    EXPECT_EQ(xyzd[0], f.cloud.points[i].x());
    EXPECT_EQ(xyzd[2], f.cloud.points[i].z());
    const float d = f.result.deviation_mm[i];
    EXPECT_TRUE(std::isnan(d) ? std::isnan(xyzd[3]) : xyzd[3] == d);
    EXPECT_TRUE(std::isnan(d) ? std::isnan(xyzd[4]) : xyzd[4] == d);
    const Rgb c = DeviationColor(d, f.result.tolerance_mm, f.result.color_range_mm);
    EXPECT_EQ(static_cast<uint8_t>(rec[20]), c.r);
    EXPECT_EQ(static_cast<uint8_t>(rec[22]), c.b);
    ++k;
  }
  EXPECT_EQ(in.peek(), EOF) << "no trailing bytes";
  EXPECT_FALSE(
      WriteErrorMapPly(path, PointCloud::Unorganized({Vector3f(50, 50, 1)}), f.result, "part").ok())
      << "size mismatch";
}

TEST(ErrorMapOutput, CsvHasOneRowPerInputPointInOrder) {
  const ScanFixture f = SmallOrganizedScan();
  TempDir dir;
  const std::string path = dir.File("map.csv");
  ASSERT_TRUE(WriteErrorMapCsv(path, f.cloud, f.result).ok());
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "x,y,z,deviation,dx,dy,dz,normal_deviation");
  std::size_t rows = 0;
  while (std::getline(in, line)) {
    const std::size_t i = rows++;
    std::vector<float> v;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ','))
      v.push_back(cell == "nan" ? NAN : std::strtof(cell.c_str(), nullptr));
    ASSERT_EQ(v.size(), 8u) << line;
    if (!PointCloud::IsValid(f.cloud.points[i])) {
      EXPECT_EQ(line, "nan,nan,nan,nan,nan,nan,nan,nan");
      continue;
    }
    EXPECT_EQ(v[0], f.cloud.points[i].x()) << "round-trip exact";
    EXPECT_EQ(v[1], f.cloud.points[i].y());
    const float d = f.result.deviation_mm[i];
    EXPECT_TRUE(std::isnan(d) ? std::isnan(v[3]) : v[3] == d) << line;
  }
  EXPECT_EQ(rows, f.cloud.size());
}

TEST(ErrorMapOutput, ReportJsonCarriesTheNumbers) {
  const ScanFixture f = SmallOrganizedScan();
  ErrorMapSettings s;
  s.split_components = true;
  const nlohmann::json j = nlohmann::json::parse(ErrorMapReportJson(f.result, s).dump());
  EXPECT_EQ(j["units"], "mm");
  EXPECT_EQ(j["points"]["count"], 1200);
  EXPECT_EQ(j["points"]["valid"], f.result.stats.valid);
  EXPECT_EQ(j["points"]["matched"], f.result.stats.matched);
  EXPECT_EQ(j["tolerance"]["verdict"], "fail");
  EXPECT_EQ(j["tolerance"]["above"], f.result.verdict.above);
  EXPECT_DOUBLE_EQ(j["statistics"]["p50_mm"].get<double>(), f.result.stats.p50_mm);
  std::size_t total = j["histogram"]["below_range"].get<std::size_t>() +
                      j["histogram"]["above_range"].get<std::size_t>();
  for (const auto& c : j["histogram"]["counts"]) total += c.get<std::size_t>();
  EXPECT_EQ(total, f.result.stats.matched);
}

TEST(ErrorMapOutput, PngOfAnOrganizedScanIsTheSensorGridWithPanel) {
  const ScanFixture f = SmallOrganizedScan();
  auto img = RenderErrorMap(f.cloud, f.result, ComputeBounds(f.index->mesh()));
  ASSERT_TRUE(img.ok()) << img.status();
  // 40 x 30 grid enlarged x10, then the 310-pixel panel; at least 520 tall.
  EXPECT_EQ(img->width, 400u + 310u);
  EXPECT_EQ(img->height, 520u);
  const ErrorMapResult& r = f.result;
  // Pixel (col 5, row 1): +0.5 mm; (15, 1): -0.5; (25, 1): in tolerance;
  // (35, 1): unmatched grey; (0, 0) is a NaN hole (index 0): white.
  EXPECT_EQ(img->at(55, 15),
            DeviationColor(r.deviation_mm[40 + 5], r.tolerance_mm, r.color_range_mm));
  EXPECT_EQ(img->at(155, 15),
            DeviationColor(r.deviation_mm[40 + 15], r.tolerance_mm, r.color_range_mm));
  EXPECT_EQ(img->at(255, 15),
            DeviationColor(r.deviation_mm[40 + 25], r.tolerance_mm, r.color_range_mm));
  EXPECT_EQ(img->at(355, 15), kUnmatchedGrey);
  EXPECT_EQ(img->at(5, 5), (Rgb{255, 255, 255}));
  TempDir dir;
  ASSERT_TRUE(
      WriteErrorMapPng(dir.File("map.png"), f.cloud, r, ComputeBounds(f.index->mesh())).ok());
  const std::string bytes = testing::ReadBytes(dir.File("map.png"));
  ASSERT_GT(bytes.size(), 24u);
  EXPECT_EQ(bytes.substr(1, 3), "PNG");
  ErrorMapPngOptions bad;
  bad.view_axis = 3;
  EXPECT_FALSE(RenderErrorMap(f.cloud, r, ComputeBounds(f.index->mesh()), bad).ok());
}

TEST(ErrorMapOutput, DefectsAreMarkedWithTheirIdsAtTheirPixel) {
  const ScanFixture f = SmallOrganizedScan();
  const std::size_t i = 15 * 40 + 25;  // row 15, col 25 of the 40 x 30 grid
  ASSERT_TRUE(PointCloud::IsValid(f.cloud.points[i]));
  std::vector<Defect> defects(1);
  defects[0].id = 7;
  defects[0].centroid_mm = f.cloud.points[i].cast<double>() + Eigen::Vector3d(0.01, 0, 0);
  ErrorMapPngOptions with;
  with.defects = &defects;
  const Bounds3 b = ComputeBounds(f.index->mesh());
  auto plain = RenderErrorMap(f.cloud, f.result, b);
  auto marked = RenderErrorMap(f.cloud, f.result, b, with);
  ASSERT_TRUE(plain.ok() && marked.ok());
  ASSERT_EQ(plain->width, marked->width);
  // The block of point i is (250..259, 150..159); the ring has radius 7
  // around its centre (255, 155), the id is drawn right of it.
  const Rgb black{0, 0, 0};
  EXPECT_EQ(marked->at(248, 155), black);
  EXPECT_EQ(marked->at(262, 155), black);
  EXPECT_EQ(marked->at(255, 148), black);
  EXPECT_EQ(marked->at(255, 155), plain->at(255, 155)) << "the ring leaves the value visible";
  std::size_t changed = 0;
  for (uint32_t y = 0; y < plain->height; ++y)
    for (uint32_t x = 0; x < plain->width; ++x) {
      if (plain->at(x, y) == marked->at(x, y)) continue;
      ++changed;
      EXPECT_TRUE(x >= 248 && x <= 280 && y >= 148 && y <= 162) << x << "," << y;
    }
  EXPECT_GT(changed, 60u) << "ring and the digit 7";
  std::vector<Defect> none;
  with.defects = &none;
  EXPECT_TRUE(RenderErrorMap(f.cloud, f.result, b, with)->pixels == plain->pixels);
  // The part verdict replaces the tolerance verdict ("fail" here) in the panel.
  ASSERT_FALSE(f.result.verdict.pass);
  with.part_pass = false;
  EXPECT_TRUE(RenderErrorMap(f.cloud, f.result, b, with)->pixels == plain->pixels);
  with.part_pass = true;
  auto passed = RenderErrorMap(f.cloud, f.result, b, with);
  auto green = [](const RgbImage& img) {
    std::size_t n = 0;
    for (uint32_t y = 0; y < 35; ++y)
      for (uint32_t x = 400; x < img.width; ++x) n += img.at(x, y) == Rgb{0, 140, 0} ? 1 : 0;
    return n;
  };
  EXPECT_GT(green(*passed), 50u) << "a green 'pass' at the panel's top";
  EXPECT_EQ(green(*plain), 0u);
  EXPECT_FALSE(passed->pixels == plain->pixels);
}

TEST(ErrorMapOutput, PngOfAMergedCloudLooksAlongTheThinnestAxis) {
  const ScanFixture f = SmallOrganizedScan();
  const PointCloud merged = PointCloud::Unorganized(f.cloud.points);  // same points, no grid
  const Bounds3 plane = ComputeBounds(f.index->mesh());
  EXPECT_EQ(ThinnestAxis(plane), 2);
  auto img = RenderErrorMap(merged, f.result, plane);
  ASSERT_TRUE(img.ok());
  // Top view: x to the right, y up; the +0.5 mm block (x < 30) is on the left.
  const uint32_t map_w = img->width - 310;
  EXPECT_GE(map_w, 300u);
  const ErrorMapResult& r = f.result;
  std::size_t red = 0, blue = 0;
  for (uint32_t y = 0; y < img->height; ++y)
    for (uint32_t x = 0; x < map_w; ++x) {
      const Rgb c = img->at(x, y);
      if (c == DeviationColor(0.5, r.tolerance_mm, r.color_range_mm)) red += x < map_w / 4 ? 1 : 0;
      if (c == DeviationColor(-0.5, r.tolerance_mm, r.color_range_mm))
        blue += x >= map_w / 4 && x < map_w / 2 ? 1 : 0;
    }
  EXPECT_GT(red, 1000u);
  EXPECT_GT(blue, 1000u);
}

}  // namespace
}  // namespace surfinspect
