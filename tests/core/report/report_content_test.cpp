// core/report/report_content.cpp: what the printed report shows, read from
// the typed report.
#include "core/report/report_content.h"

#include <gtest/gtest.h>

#include "core/pipeline/inspection_report.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

// What the printed report shows of a report.json object: decoded, then read.
absl::StatusOr<ReportContent> ReportContentFromJson(const nlohmann::json& j) {
  ASSIGN_OR_RETURN(InspectionReport report, DecodeReport(j));
  return ReportContentFrom(report);
}

nlohmann::json Report() {
  return nlohmann::json::parse(R"({
    "verdict": "fail",
    "tolerance": {"band_mm": 0.2, "verdict": "pass", "reason": "all within", "fraction_within": 0.995,
                  "above": 3, "below": 2},
    "color_range_mm": 0.5,
    "points": {"count": 10, "valid": 9, "matched": 8},
    "statistics": {"min_mm": -0.25, "max_mm": 0.31, "mean_mm": 0.0125, "stddev_mm": null,
                   "rms_mm": 0.1, "p1_mm": -0.2, "p5_mm": -0.1, "p50_mm": 0, "p95_mm": 0.1,
                   "p99_mm": 0.2},
    "histogram": {"min_mm": -0.5, "max_mm": 0.5, "counts": [1, 6, 1], "below_range": 0,
                  "above_range": 0},
    "characteristics": [
      {"name": "ok-region", "type": "region", "verdict": "pass", "reason": "",
       "tolerance_mm": {"lower": -0.2, "upper": 0.2}, "points": 5, "min_mm": -0.1,
       "max_mm": 0.1, "mean_mm": 0.01, "fraction_within": 1.0},
      {"name": "bad point", "type": "point", "verdict": "fail", "reason": "above",
       "tolerance_mm": {"lower": -0.1, "upper": 0.1}, "points": 1, "min_mm": 0.3,
       "max_mm": 0.3, "mean_mm": 0.3, "value_mm": 0.3004, "fraction_within": 0.0},
      {"name": "unseen", "type": "point", "verdict": "fail", "reason": "no points",
       "tolerance_mm": {"lower": -0.1, "upper": 0.1}, "points": 0, "min_mm": null,
       "max_mm": null, "mean_mm": null, "value_mm": null, "fraction_within": null}],
    "defects": [{"id": 4, "kind": "dent", "centroid_mm": [1.0, 2.0, 3.5], "area_mm2": 12.25,
                 "extent_mm": 4.0, "peak_mm": -0.3, "peak_source": "fit", "points": 40, "region": "ridge"}]
  })");
}

TEST(ReportContent, FailedCharacteristicsComeFirstInReportOrder) {
  auto c = ReportContentFromJson(Report());
  ASSERT_TRUE(c.ok()) << c.status();
  ASSERT_EQ(c->characteristics.rows.size(), 3u);
  EXPECT_EQ(c->characteristics.rows[0][0], "bad point");
  EXPECT_EQ(c->characteristics.rows[1][0], "unseen");
  EXPECT_EQ(c->characteristics.rows[2][0], "ok-region");
  EXPECT_EQ(c->characteristics.failed, (std::vector<bool>{true, true, false}));
  // A point shows its value, a region its mean; null prints "-".
  EXPECT_EQ(c->characteristics.rows[0][4], "+0.300");
  EXPECT_EQ(c->characteristics.rows[2][4], "+0.010");
  EXPECT_EQ(c->characteristics.rows[1][4], "-");
  EXPECT_EQ(c->characteristics.rows[0][3], "-0.100 / +0.100");
  EXPECT_EQ(c->characteristics.rows[2][7], "100.00 %");
  EXPECT_EQ(c->characteristics.rows[1][8], "0");
  for (const auto& row : c->characteristics.rows)
    EXPECT_EQ(row.size(), c->characteristics.header.size());
}

TEST(ReportContent, PlanVerdictWinsOverTheToleranceVerdict) {
  auto c = ReportContentFromJson(Report());
  ASSERT_TRUE(c.ok());
  EXPECT_EQ(c->verdict, "fail");
  EXPECT_FALSE(c->pass);
  nlohmann::json plain = Report();
  plain.erase("verdict");
  plain.erase("characteristics");
  plain.erase("defects");
  auto p = ReportContentFromJson(plain);
  ASSERT_TRUE(p.ok());
  EXPECT_EQ(p->verdict, "pass");
  EXPECT_TRUE(p->pass);
  EXPECT_TRUE(p->characteristics.rows.empty());
  EXPECT_EQ(p->reason, "all within");
}

TEST(ReportContent, DefectsStatisticsAndHistogram) {
  auto c = ReportContentFromJson(Report());
  ASSERT_TRUE(c.ok());
  ASSERT_EQ(c->defect_marks.size(), 1u);
  EXPECT_EQ(c->defect_marks[0].id, 4);
  EXPECT_EQ(c->defect_marks[0].centroid_mm, Eigen::Vector3d(1.0, 2.0, 3.5));
  EXPECT_EQ(c->defects.rows[0], (std::vector<std::string>{"4", "dent", "ridge", "-0.300", "fit",
                                                          "12.2", "4.0", "40", "1.0, 2.0, 3.5"}));
  EXPECT_EQ(c->histogram.counts, (std::vector<std::size_t>{1, 6, 1}));
  EXPECT_DOUBLE_EQ(c->tolerance_mm, 0.2);
  EXPECT_DOUBLE_EQ(c->color_range_mm, 0.5);
  auto find = [&](const std::string& label) {
    for (const auto& [l, v] : c->statistics)
      if (l == label) return v;
    return std::string("missing");
  };
  EXPECT_EQ(find("max"), "+0.310");
  EXPECT_EQ(find("std dev"), "-");
  EXPECT_EQ(find("matched"), "8");
  EXPECT_EQ(find("in tolerance"), "99.50 %");
  EXPECT_EQ(find("tolerance"), "+-0.200 mm");
}

TEST(ReportContent, OptionalSectionsMayBeMissing) {
  nlohmann::json j = Report();
  for (const char* key : {"histogram", "statistics", "points", "characteristics", "defects"})
    j.erase(key);
  auto c = ReportContentFromJson(j);
  ASSERT_TRUE(c.ok()) << c.status();
  EXPECT_TRUE(c->histogram.counts.empty());
  EXPECT_TRUE(c->characteristics.rows.empty());
  EXPECT_TRUE(c->defect_marks.empty());
  for (const auto& [label, value] : c->statistics)
    if (label != "tolerance" && label != "in tolerance" && label != "above/below") {
      EXPECT_EQ(value, "-") << label;
    }
}

TEST(ReportContent, MissingFieldsAreDataLossNamingThem) {
  for (const char* key : {"tolerance", "color_range_mm"}) {
    nlohmann::json j = Report();
    j.erase(key);
    auto c = ReportContentFromJson(j);
    ASSERT_FALSE(c.ok()) << key;
    EXPECT_EQ(c.status().code(), absl::StatusCode::kDataLoss) << key;
    EXPECT_NE(c.status().message().find(key), std::string::npos) << c.status();
  }
  nlohmann::json bad = Report();
  bad["color_range_mm"] = 0;
  EXPECT_FALSE(ReportContentFromJson(bad).ok());
  bad = Report();
  bad["defects"][0]["centroid_mm"] = "here";
  EXPECT_FALSE(ReportContentFromJson(bad).ok());
  bad = Report();
  bad["histogram"]["counts"] = "many";
  EXPECT_EQ(ReportContentFromJson(bad).status().code(), absl::StatusCode::kDataLoss);
  bad = Report();
  bad.erase("verdict");
  bad["tolerance"].erase("verdict");
  EXPECT_FALSE(ReportContentFromJson(bad).ok()) << "no verdict at all";
}

ReportCharacteristic Hole(const std::string& name, const std::string& type) {
  ReportCharacteristic c;
  c.name = name;
  c.type = type;
  c.verdict = "pass";
  c.tolerance = {-0.1, 0.1};
  c.position_tolerance_mm = 0.3;
  c.points = 180;
  c.measured_position_mm = {10.1, 20, 5};
  c.position_deviation_mm = {0.1, 0, 0};
  c.true_position_mm = 0.2;
  c.measured_diameter_mm = 8.012;
  c.diameter_deviation_mm = 0.012;
  c.arc_coverage_deg = 351.2;
  if (type == "slot") {
    c.length_tolerance = {-0.2, 0.3};
    c.measured_length_mm = 14.1;
    c.length_deviation_mm = 0.1;
  }
  return c;
}

TEST(ReportContent, HoleRowsShowSizeTruePositionAndArc) {
  ReportCharacteristic h = Hole("H1", "hole");
  h.verdict = "fail";
  h.true_position_mm = 0.31;
  const std::vector<std::string> row = CharacteristicRow(h);
  ASSERT_EQ(row.size(), CharacteristicHeader().size());
  EXPECT_EQ(row[3], "\u00d8 -0.100 / +0.100\nTP 0.300");
  EXPECT_EQ(row[4], "\u00d8 8.012 (+0.012)\nTP 0.310 / 0.300");
  EXPECT_EQ(row[5], "-") << "no surface statistics for a hole";
  EXPECT_EQ(row[7], "arc 351\u00b0");
  EXPECT_EQ(row[8], "180");
  const std::vector<std::string> slot = CharacteristicRow(Hole("S1", "slot"));
  EXPECT_EQ(slot[3], "W -0.100 / +0.100\nL -0.200 / +0.300\nTP 0.300");
  EXPECT_EQ(slot[4], "W 8.012 (+0.012)\nL 14.100 (+0.100)\nTP 0.200 / 0.300");
  ReportCharacteristic unseen = Hole("H9", "hole");
  unseen.verdict = "not_measured";
  unseen.measured_diameter_mm = unseen.true_position_mm = NAN;
  unseen.arc_coverage_deg = 120;
  const std::vector<std::string> u = CharacteristicRow(unseen);
  EXPECT_EQ(u[4], "-");
  EXPECT_EQ(u[7], "arc 120\u00b0") << "how much of its edge was seen says why";
}

// Each part of a hole is judged by the rule that made the hole's verdict.
TEST(ReportContent, HoleVerdictsJudgeEachPart) {
  ReportCharacteristic h = Hole("H1", "hole");
  h.true_position_mm = 0.31;
  HoleVerdicts v = HoleVerdictsOf(h);
  EXPECT_EQ(v.size, "pass");
  EXPECT_EQ(v.position, "fail");
  EXPECT_EQ(v.length, "");
  h.true_position_mm = 0.3;  // on the zone's boundary: inside
  h.diameter_deviation_mm = -0.1001;
  v = HoleVerdictsOf(h);
  EXPECT_EQ(v.size, "fail");
  EXPECT_EQ(v.position, "pass");
  ReportCharacteristic s = Hole("S1", "slot");
  s.length_deviation_mm = 0.31;
  EXPECT_EQ(HoleVerdictsOf(s).length, "fail");
  s.verdict = "not_measured";
  v = HoleVerdictsOf(s);
  EXPECT_EQ(v.size, "not_measured");
  EXPECT_EQ(v.length, "not_measured");
  EXPECT_EQ(v.position, "not_measured");
}

TEST(ReportContent, FormatMm) {
  EXPECT_EQ(FormatMm(0.1234), "+0.123");
  EXPECT_EQ(FormatMm(-2), "-2.000");
  EXPECT_EQ(FormatMm(NAN), "-");
  EXPECT_EQ(FormatMm(INFINITY), "-");
}

}  // namespace
}  // namespace surfinspect
