// core/pipeline/report_alignment.cpp and the "alignment" of report.json: a
// calibrated plan writes none (other reports keep their bytes); an RPS
// outcome's correction, references and locked directions are carried as
// made; the codec round trips them; a bad matrix is refused naming it.
#include "core/pipeline/report_alignment.h"

#include <gtest/gtest.h>

#include "core/pipeline/inspection_report.h"

namespace surfinspect {
namespace {

PlanOutcome WithRps() {
  PlanOutcome o;
  AlignmentOutcome& a = o.alignment;
  a.mode = AlignmentMode::kRps;
  a.aligned = true;
  a.x << 0.1, -0.2, 0.3, 0.001, -0.002, 0.003;
  a.correction = RigidMotion(a.x).transform();
  a.correction_mm = 0.41;
  a.correction_deg = 0.21;
  a.max_correction_mm = 2;
  a.max_correction_deg = 1;
  a.rms_before_mm = 0.2;
  a.rms_after_mm = 0.004;
  a.dofs = 6;
  AlignmentReferenceResult hole{"A1", "hole", true, {-110, 0, 60}, {-109.9, 0.2, 60}, {}, {},
                                {},   88,     ""};
  hole.directions = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY()};
  hole.before_mm = {0.1, 0.2};
  hole.after_mm = {0.001, -0.002};
  a.references = {hole};
  return o;
}

TEST(ReportAlignment, CarriesTheOutcomeAndNothingForTheCalibratedFrame) {
  EXPECT_FALSE(ReportAlignmentOf(PlanOutcome{}).has_value());
  const auto r = ReportAlignmentOf(WithRps());
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->mode, "rps");
  ASSERT_EQ(r->matrix.size(), 16u);
  EXPECT_EQ(r->matrix[3], WithRps().alignment.correction.translation().x());
  EXPECT_EQ(r->matrix[15], 1.0);
  EXPECT_EQ(r->translation_mm, Eigen::Vector3d(0.1, -0.2, 0.3));
  EXPECT_NEAR(r->rotation_deg.z(), 0.003 * 180 / M_PI, 1e-12);
  ASSERT_EQ(r->references.size(), 1u);
  ASSERT_EQ(r->references[0].locked.size(), 2u);
  EXPECT_EQ(r->references[0].locked[1].direction, Eigen::Vector3d::UnitY());
  EXPECT_EQ(r->references[0].locked[1].after_mm, -0.002);
  EXPECT_TRUE(r->locked.empty()) << "locked DOFs are a best-fit's";
}

TEST(ReportAlignment, RoundTripsThroughTheCodec) {
  InspectionReport report;
  report.schema = kReportSchema;
  report.verdict = "pass";
  EXPECT_EQ(ReportText(report).find("\"alignment\""), std::string::npos);
  report.alignment = ReportAlignmentOf(WithRps());
  const std::string text = ReportText(report);
  auto back = ParseReport(text);
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_TRUE(back->alignment.has_value());
  EXPECT_EQ(ReportText(*back), text);
  EXPECT_EQ(back->alignment->references[0].nominal_mm, Eigen::Vector3d(-110, 0, 60));
}

TEST(ReportAlignment, ABadMatrixIsRefusedNamingIt) {
  InspectionReport report;
  report.schema = kReportSchema;
  report.verdict = "pass";
  report.alignment = ReportAlignmentOf(WithRps());
  nlohmann::json j = EncodeReport(report);
  j["alignment"]["matrix"] = {1, 2, 3};
  auto back = DecodeReport(j);
  ASSERT_FALSE(back.ok());
  EXPECT_EQ(back.status().message(), "report.alignment.matrix: not 16 numbers");
}

}  // namespace
}  // namespace surfinspect
