// core/pipeline/report_coverage.cpp and the "coverage" of report.json: the
// triangles listed are those not wholly covered, fractions rounded to
// 0.001; the codec's round trip (struct and bytes); a report without
// coverage keeps its bytes; bad columns are refused naming the field.
#include "core/pipeline/report_coverage.h"

#include <gtest/gtest.h>

#include "core/pipeline/inspection_report.h"

namespace surfinspect {
namespace {

PlanOutcome WithCoverage(std::vector<float> triangles) {
  PlanOutcome outcome;
  outcome.coverage_run = true;
  outcome.coverage.distance_mm = 0.98765;
  outcome.coverage.surface = 0.83333;
  outcome.coverage.triangles = std::move(triangles);
  return outcome;
}

TEST(ReportCoverage, ListsTheTrianglesNotWhollySeenRounded) {
  const auto c = ReportCoverageOf(WithCoverage({1.f, 0.f, 0.25049f, 0.99951f, 0.9994f, 1.f}));
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->distance_mm, 0.988);
  EXPECT_EQ(c->surface, 0.833);
  EXPECT_EQ(c->triangles, (std::vector<std::size_t>{1, 2, 4})) << "0.99951 rounds to 1: seen";
  EXPECT_EQ(c->covered, (std::vector<double>{0, 0.25, 0.999}));
  EXPECT_FALSE(ReportCoverageOf(PlanOutcome{}).has_value()) << "coverage not run";
}

TEST(ReportCoverage, RoundTripsThroughTheCodecAndIsAbsentWithoutCoverage) {
  InspectionReport report;
  report.schema = kReportSchema;
  report.verdict = "pass";
  const std::string without = ReportText(report);
  EXPECT_EQ(without.find("\"coverage\""), std::string::npos);
  report.coverage = ReportCoverageOf(WithCoverage({0.5f, 1.f, 0.f}));
  const std::string text = ReportText(report);
  auto back = ParseReport(text);
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_TRUE(back->coverage.has_value());
  EXPECT_EQ(back->coverage->triangles, report.coverage->triangles);
  EXPECT_EQ(back->coverage->covered, report.coverage->covered);
  EXPECT_EQ(back->coverage->surface, report.coverage->surface);
  EXPECT_EQ(ReportText(*back), text);
}

TEST(ReportCoverage, RefusesColumnsThatDoNotFit) {
  ReportCoverage c;
  c.triangles = {3, 5};
  c.covered = {0.5};
  EXPECT_NE(CheckReportCoverage(c).message().find("report.coverage.covered"), std::string::npos);
  c.covered = {0.5, 1.5};
  EXPECT_EQ(CheckReportCoverage(c).code(), absl::StatusCode::kDataLoss);
  c.covered = {0.5, 0.5};
  c.triangles = {5, 3};
  EXPECT_NE(CheckReportCoverage(c).message().find("report.coverage.triangles"), std::string::npos);
  c.triangles = {3, 5};
  EXPECT_TRUE(CheckReportCoverage(c).ok());
  EXPECT_TRUE(CheckReportCoverage(std::nullopt).ok());
}

}  // namespace
}  // namespace surfinspect
