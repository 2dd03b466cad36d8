// client/cell/part_outputs.cpp: the files a part leaves, result.qif among
// them when the report is a surfinspect.report/2.
#include "client/cell/part_outputs.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "tests/support/temp_dir.h"

namespace surfinspect::client {
namespace {

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
      R"({"schema": "surfinspect.report/2", "verdict": "pass", "characteristics": [
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
  ASSERT_TRUE(WritePartOutputs(dir.path(), Outputs(R"({"tolerance": {"band_mm": 0.1}})")).ok());
  EXPECT_FALSE(std::filesystem::exists(dir.File("result.qif")));
  EXPECT_TRUE(std::filesystem::exists(dir.File("report.json")));
  EXPECT_TRUE(std::filesystem::exists(dir.File("errormap.ply")));
}

TEST(PartOutputs, ABadReport2IsAnErrorAndNoReportIsWritten) {
  testing::TempDir dir;
  const auto st = WritePartOutputs(
      dir.path(), Outputs(R"({"schema": "surfinspect.report/2", "verdict": "maybe"})"));
  EXPECT_EQ(st.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_FALSE(std::filesystem::exists(dir.File("report.json")));  // the part is not complete
}

}  // namespace
}  // namespace surfinspect::client
