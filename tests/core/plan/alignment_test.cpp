// core/plan/alignment.cpp apart from the pipeline (the end to end tests
// against the simulator's truth are tests/core/pipeline/
// inspection_alignment_test.cpp): the calibrated frame measures nothing;
// a reference the scan does not reach is a failure naming it, never a
// correction; a failed or excessive alignment fails the part, its reason
// first.
#include "core/plan/alignment.h"

#include <gtest/gtest.h>

#include "core/simulation/pillar.h"

namespace surfinspect {
namespace {

struct Fixture {
  TriangleMesh part = MakePillarMesh(300);
  std::unique_ptr<MeshIndex> index = *MeshIndex::Build(part);
  PointCloud cloud;  // no points
  std::vector<PlanView> views;
  AlignmentInputs in{*index, cloud, Eigen::Isometry3d::Identity(), views, 5.0, 1};
};

TEST(Alignment, TheCalibratedFrameMeasuresNothing) {
  Fixture f;
  auto a = MeasureAlignment(f.in, InspectionPlan{});
  ASSERT_TRUE(a.ok()) << a.status();
  EXPECT_EQ(a->mode, AlignmentMode::kCalibrated);
  EXPECT_FALSE(a->aligned);
  EXPECT_TRUE(a->ok());
  EXPECT_TRUE(a->correction.isApprox(Eigen::Isometry3d::Identity()));
}

TEST(Alignment, AnUnseenReferenceIsAFailureNamingIt) {
  Fixture f;
  InspectionPlan plan;
  plan.alignment.mode = AlignmentMode::kRps;
  plan.alignment.references = {{"B1", "", {0, 0, PillarRidgeZ(0, 300)}, 3.0}};
  auto a = MeasureAlignment(f.in, plan);
  ASSERT_TRUE(a.ok()) << a.status();
  EXPECT_FALSE(a->aligned);
  EXPECT_EQ(a->failure, "reference B1: 0 points within its radius, at least 20 needed");
  ASSERT_EQ(a->references.size(), 1u);
  EXPECT_EQ(a->references[0].kind, "surface");
  EXPECT_FALSE(a->references[0].measured);
}

TEST(Alignment, AnUnmeasuredHoleReferenceIsAFailureWithTheHolesReason) {
  Fixture f;
  InspectionPlan plan;
  PlanHole h;
  h.name = "H1";
  h.position_mm = {-110, 0, PillarRidgeZ(-110, 300)};
  h.diameter_mm = 8;
  plan.holes = {h};
  plan.alignment.mode = AlignmentMode::kRps;
  plan.alignment.references = {{"A1", "H1", Eigen::Vector3d::Zero(), 3.0}};
  auto a = MeasureAlignment(f.in, plan);
  ASSERT_TRUE(a.ok()) << a.status();
  EXPECT_FALSE(a->aligned);
  EXPECT_EQ(a->failure,
            "reference A1: its hole was not measured (no organized views (holes are measured by "
            "inspect))");
}

TEST(Alignment, AFailedOrExcessiveAlignmentFailsThePartReasonFirst) {
  CharacteristicsResult passed;
  passed.pass = true;
  AlignmentOutcome fine;
  fine.mode = AlignmentMode::kRps;
  CharacteristicsResult r = passed;
  ApplyAlignmentVerdict(fine, &r);
  EXPECT_TRUE(r.pass);
  AlignmentOutcome failed = fine;
  failed.failure = "reference B1: 3 points within its radius, at least 20 needed";
  r = passed;
  ApplyAlignmentVerdict(failed, &r);
  EXPECT_FALSE(r.pass);
  EXPECT_EQ(r.reason, "alignment (rps) failed: " + failed.failure);
  AlignmentOutcome excessive = fine;
  excessive.mode = AlignmentMode::kBestFit;
  excessive.aligned = true;
  excessive.correction_mm = 2.5;
  excessive.correction_deg = 0.2;
  excessive.max_correction_mm = 2;
  excessive.max_correction_deg = 1;
  excessive.within_max_correction = false;
  r = passed;
  r.reason = "ridge: 3% outside";
  ApplyAlignmentVerdict(excessive, &r);
  EXPECT_FALSE(r.pass);
  EXPECT_EQ(r.reason,
            "alignment (best_fit) corrects 2.500 mm / 0.200 deg, more than the 2 mm / 1 deg "
            "allowed; ridge: 3% outside");
}

}  // namespace
}  // namespace surfinspect
