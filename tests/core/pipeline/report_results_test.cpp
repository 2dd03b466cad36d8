// A hole's measurement as the report carries it: every field from the
// result, through report.json and back.
#include "core/pipeline/report_results.h"

#include <gtest/gtest.h>

namespace surfinspect {
namespace {

CharacteristicResult MeasuredSlot() {
  CharacteristicResult c;
  c.name = "S1";
  c.type = CharacteristicType::kSlot;
  c.pass = false;
  c.reason = "fail: true position 0.412 mm > 0.2 mm";
  c.tolerance = {-0.1, 0.1};
  c.position_tolerance_mm = 0.2;
  c.length_tolerance = {-0.2, 0.3};
  c.points = 412;
  HoleMeasurement& h = c.hole;
  h.measured = true;
  h.measured_position_mm = {95.2, -7.9, 58.8};
  h.position_deviation_mm = {0.2, 0.1, 0.0};
  h.true_position_mm = 0.412;
  h.diameter_mm = 6.05;
  h.diameter_deviation_mm = 0.05;
  h.length_mm = 14.1;
  h.length_deviation_mm = 0.1;
  h.form_mm = 0.03;
  h.arc_coverage_deg = 351;
  h.pixel_pitch_mm = 0.25;
  h.edge_points = 412;
  return c;
}

TEST(ReportResults, ASlotsFieldsGoThroughReportJson) {
  const ReportCharacteristic r = ReportCharacteristicOf(MeasuredSlot());
  EXPECT_EQ(r.type, "slot");
  EXPECT_EQ(r.verdict, "fail");
  EXPECT_EQ(r.measured_position_mm, Eigen::Vector3d(95.2, -7.9, 58.8));
  EXPECT_EQ(r.true_position_mm, 0.412);
  EXPECT_EQ(r.measured_diameter_mm, 6.05);
  EXPECT_EQ(r.measured_length_mm, 14.1);
  EXPECT_EQ(r.length_tolerance.upper_mm, 0.3);
  EXPECT_EQ(r.arc_coverage_deg, 351);
  InspectionReport report;
  report.schema = kReportSchema;
  report.characteristics = {r};
  const nlohmann::json j = EncodeReport(report);
  const nlohmann::json& c = j["characteristics"][0];
  EXPECT_EQ(c["measured_width_mm"], 6.05) << "a slot's size is its width";
  EXPECT_FALSE(c.contains("measured_diameter_mm"));
  EXPECT_EQ(c["length_tolerance_mm"]["upper"], 0.3);
  EXPECT_FALSE(c.contains("allowed_fraction_outside"));
  auto back = DecodeReport(j);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->characteristics[0], r);
  EXPECT_EQ(EncodeReport(*back), j);
}

TEST(ReportResults, AHoleNotMeasuredHasNullsNotNumbers) {
  CharacteristicResult c;
  c.name = "H9";
  c.type = CharacteristicType::kHole;
  c.measured = false;
  c.reason = "not measured: edge seen over 120 deg, at least 180 needed";
  c.position_tolerance_mm = 0.2;
  const ReportCharacteristic r = ReportCharacteristicOf(c);
  EXPECT_EQ(r.verdict, "not_measured");
  InspectionReport report;
  report.schema = kReportSchema;
  report.characteristics = {r};
  const nlohmann::json j = EncodeReport(report);
  EXPECT_TRUE(j["characteristics"][0]["measured_position_mm"].is_null());
  EXPECT_TRUE(j["characteristics"][0]["measured_diameter_mm"].is_null());
  auto back = DecodeReport(j);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->characteristics[0], r);
}

}  // namespace
}  // namespace surfinspect
