// client/cell/part_outputs.cpp: the files a part leaves. report.html is
// written with the others, before report.json, in the part frame, with the
// cell's name and calibration status; result.qif when the report is a
// surfinspect.report/2.
#include "client/cell/part_outputs.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "client/cell/report_context.h"
#include "tests/support/temp_dir.h"

namespace surfinspect::client {
namespace {

PartOutputs SmallPart() {
  PartOutputs o;
  o.part_id = "p-1";
  o.verdict = "pass";
  o.report_json = R"({"verdict": "pass", "tolerance": {"band_mm": 0.3}, "color_range_mm": 1.0,)"
                  R"( "statistics": {"min_mm": -0.125, "max_mm": 0.25}})";
  o.png = "png";
  o.merged_in_world = PointCloud::Unorganized({{10, 0, 0}, {11, 0, 0}, {10, 1, 0}});
  o.deviation_mm = {-0.125f, 0.0f, 0.25f};
  o.tolerance_mm = 0.3;
  o.color_range_mm = 1.0;
  o.cell = "cell-\"A\"";
  o.world_from_part = Eigen::Translation3d(10, 0, 0) * Eigen::Isometry3d::Identity();
  o.viewpoints = {{"v1", true, {{"rms_mm", 0.0142}}}, {"v2", false, nullptr}};
  return o;
}

TEST(PartOutputs, WritesReportHtmlInThePartFrame) {
  testing::TempDir dir;
  ASSERT_TRUE(WritePartOutputs(dir.path(), SmallPart()).ok());
  const std::string html = testing::ReadBytes(dir.File("report.html"));
  EXPECT_NE(html.find("cell-&quot;A&quot;"), std::string::npos);
  EXPECT_NE(html.find("<td>v2</td><td class=\"fail\">not calibrated</td>"), std::string::npos);
  // The points' box starts at the part frame's origin: world x 10 is part x 0.
  const auto at = html.find("\"min\":[");
  ASSERT_NE(at, std::string::npos);
  EXPECT_EQ(html.substr(at, 12), "\"min\":[0.0,0");
  EXPECT_TRUE(std::filesystem::exists(dir.File("report.json")));
}

TEST(PartOutputs, ReportJsonOnlyAfterReportHtml) {
  testing::TempDir dir;
  // report.html cannot be written: a folder is in its place.
  std::filesystem::create_directories(dir.File("report.html/blocked"));
  EXPECT_FALSE(WritePartOutputs(dir.path(), SmallPart()).ok());
  EXPECT_FALSE(std::filesystem::exists(dir.File("report.json")));
}

TEST(ReportContext, ViewpointCalibrationsFromTheCellFile) {
  CellConfig cell;
  cell.viewpoints.resize(2);
  cell.viewpoints[0].name = "v1";
  cell.viewpoints[0].world_from_sensor = Eigen::Isometry3d::Identity();
  cell.viewpoints[1].name = "v2";
  cell.raw = nlohmann::json::parse(
      R"({"viewpoints": [{"name": "v1", "calibration": {"rms_mm": 0.0142, "converged": true}},)"
      R"( {"name": "v2"}]})");
  const auto v = ViewpointCalibrations(cell);
  ASSERT_EQ(v.size(), 2u);
  EXPECT_TRUE(v[0].calibrated);
  EXPECT_EQ(v[0].quality["rms_mm"], 0.0142);
  EXPECT_FALSE(v[1].calibrated);
  EXPECT_TRUE(v[1].quality.is_null());
}

PartOutputs Outputs(const std::string& report_json) {
  PartOutputs o;
  o.part_id = "p-7";
  o.cell = "cell-a";
  o.report_json = report_json;
  o.tolerance_mm = 0.1;
  o.color_range_mm = 0.2;
  o.merged_in_world = PointCloud::Organized(2, 1);
  o.deviation_mm = {0.01f, -0.02f};
  return o;
}

TEST(PartOutputs, Report2GetsAQifBesideTheReport) {
  testing::TempDir dir;
  const std::string report =
      R"({"schema": "surfinspect.report/2", "verdict": "pass", "tolerance": {"band_mm": 0.1},
        "color_range_mm": 0.2, "characteristics": [
        {"name": "surface", "type": "surface", "verdict": "pass", "reason": "ok",
         "tolerance_mm": {"lower": -0.1, "upper": 0.1}, "points": 2,
         "min_mm": -0.02, "max_mm": 0.01}]})";
  ASSERT_TRUE(WritePartOutputs(dir.path(), Outputs(report)).ok());
  const std::string qif = testing::ReadBytes(dir.File("result.qif"));
  EXPECT_NE(qif.find("<SerialNumber>p-7</SerialNumber>"), std::string::npos);
  EXPECT_NE(qif.find("<Name>cell-a</Name>"), std::string::npos);
  EXPECT_NE(qif.find("<URI>errormap.ply</URI>"), std::string::npos);
  EXPECT_NE(qif.find("<Value>0.04</Value>"), std::string::npos);  // 2 * max(|min|, |max|)
  EXPECT_EQ(testing::ReadBytes(dir.File("report.json")), report);
}

TEST(PartOutputs, OtherReportSchemasGetNoQifAndTheRestIsWritten) {
  testing::TempDir dir;
  ASSERT_TRUE(
      WritePartOutputs(
          dir.path(),
          Outputs(R"({"tolerance": {"band_mm": 0.1}, "color_range_mm": 0.2, "verdict": "pass"})"))
          .ok());
  EXPECT_FALSE(std::filesystem::exists(dir.File("result.qif")));
  EXPECT_TRUE(std::filesystem::exists(dir.File("report.json")));
  EXPECT_TRUE(std::filesystem::exists(dir.File("errormap.ply")));
}

TEST(PartOutputs, ABadReport2IsAnErrorAndNoReportIsWritten) {
  testing::TempDir dir;
  const auto st = WritePartOutputs(
      dir.path(), Outputs(R"({"schema": "surfinspect.report/2", "verdict": "maybe",)"
                          R"( "tolerance": {"band_mm": 0.1}, "color_range_mm": 0.2})"));
  EXPECT_EQ(st.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_FALSE(std::filesystem::exists(dir.File("report.json")));  // the part is not complete
}

}  // namespace
}  // namespace surfinspect::client
