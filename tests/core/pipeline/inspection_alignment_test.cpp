// Alignment end to end (core/plan/alignment.cpp through InspectPart) on
// simulated demo parts displaced in their fixture by known amounts (the
// simulator's truth, DemoPart::in_fixture): RPS on two holes and four
// surface points recovers the placement within pitch-bounded limits (the
// in-plane terms rest on the hole centres); the surface judged after RPS
// equals the surface judged under the true placement; a bent ridge still
// fails after RPS while a whole-part best-fit hides part of it (and says
// so); locked degrees of freedom stay exactly zero; a correction beyond the
// allowed maximum fails the part with that reason.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <iostream>
#include <nlohmann/json.hpp>
#include <random>

#include "core/pipeline/inspection.h"
#include "core/pipeline/inspection_report.h"
#include "core/plan/cad_holes.h"
#include "core/simulation/demo_cell.h"
#include "core/simulation/pillar.h"
#include "tests/support/demo_scans.h"

namespace surfinspect {
namespace {

using Eigen::Vector3d;
using nlohmann::json;

// The bounds at the demo's ~0.27 mm pitch: 0.15 pitch at the
// part's extent, 0.1 pixel over the ~145 mm between the locating holes.
constexpr double kPoseBoundMm = 0.04;
constexpr double kAngleBoundDeg = 0.01;

class InspectionAlignment : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    cell_ = new DemoCell(MakeDemoCell());
    auto index = MeshIndex::Build(cell_->part);
    ASSERT_TRUE(index.ok()) << index.status();
    index_ = index->release();
  }
  static void TearDownTestSuite() {
    delete index_;
    delete cell_;
  }

  // The surface band, the CAD's holes, a ridge region, and the alignment.
  static json Plan(const json& alignment) {
    const json holes = PlanHolesJson(ListHoles(cell_->part), 0.3);
    json plan = {{"tolerance_mm", {{"lower", -0.3}, {"upper", 0.3}}},
                 {"min_coverage", 0},
                 {"holes", holes["holes"]},
                 {"slots", holes["slots"]},
                 {"regions",
                  {{{"name", "ridge"},
                    {"select", {{"box_mm", {{-20, -20, 0}, {30, 20, 200}}}}},
                    {"tolerance_mm", {{"lower", -0.15}, {"upper", 0.15}}}}}}};
    if (!alignment.is_null()) plan["alignment"] = alignment;
    return plan;
  }

  // RPS: the two round holes of the top lock x and y (and the turn about
  // z); four surface points on the top and the flanges lock z and the tilts.
  static json Rps() { return DemoRpsAlignment(*cell_); }

  static absl::StatusOr<InspectionResult> Inspect(const testing::ScannedPart& s, const json& plan,
                                                  const Eigen::Isometry3d& world_from_part) {
    InspectionSettings settings;
    settings.filter = false;  // ScanDemoPart filtered the views
    auto parsed = ParseInspectionPlan(plan, cell_->part);
    if (!parsed.ok()) return parsed.status();
    settings.plan = *parsed;
    return InspectPart(*index_, world_from_part, s.views, settings);
  }

  static const CharacteristicResult& Named(const InspectionResult& r, const std::string& name) {
    for (const auto& c : r.plan.characteristics.characteristics)
      if (c.name == name) return c;
    ADD_FAILURE() << "no characteristic " << name;
    return r.plan.characteristics.characteristics.front();
  }

  static DemoCell* cell_;
  static MeshIndex* index_;
};

DemoCell* InspectionAlignment::cell_ = nullptr;
MeshIndex* InspectionAlignment::index_ = nullptr;

// A displacement of 0.1-1 mm and 0.05-0.5 degrees about a random axis
// through a random point of the part.
Eigen::Isometry3d RandomFixture(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1, 1), size(0.1, 1.0), angle(0.05, 0.5);
  Vector3d dir(u(rng), u(rng), u(rng)), axis(u(rng), u(rng), u(rng));
  const Vector3d about(100 * u(rng), 40 * u(rng), 30);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translate(size(rng) * dir.normalized() + about);
  t.rotate(Eigen::AngleAxisd(angle(rng) * M_PI / 180, axis.normalized()));
  t.translate(-about);
  return t;
}

// The largest distance between the two transforms' images of the part's
// bounding-box corners, and the angle between their rotations.
std::pair<double, double> PoseError(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  double worst = 0;
  for (double x : {-150, 150})
    for (double y : {-76, 76})
      for (double z : {-10, 70})
        worst = std::max(worst, (a * Vector3d(x, y, z) - b * Vector3d(x, y, z)).norm());
  return {worst, Eigen::AngleAxisd(a.linear() * b.linear().transpose()).angle() * 180 / M_PI};
}

TEST_F(InspectionAlignment, RpsRecoversTheFixtureDisplacementAndJudgesAsTheTruth) {
  std::mt19937_64 rng(21);
  for (uint64_t seed : {31, 32, 33}) {
    DemoPart part;
    part.number = int(seed);
    part.in_fixture = RandomFixture(rng);
    const testing::ScannedPart s = testing::ScanDemoPart(*cell_, part, seed);
    auto rps = Inspect(s, Plan(Rps()), cell_->world_from_part);
    ASSERT_TRUE(rps.ok()) << rps.status();
    const AlignmentOutcome& a = rps->plan.alignment;
    ASSERT_TRUE(a.aligned) << a.failure;
    EXPECT_TRUE(a.ok()) << a.failure;
    EXPECT_EQ(a.references.size(), 6u);
    const auto [mm, deg] = PoseError(a.correction, part.in_fixture.inverse());
    std::cout << "seed " << seed << ": placement off "
              << PoseError(Eigen::Isometry3d::Identity(), part.in_fixture.inverse()).first
              << " mm; after RPS " << mm << " mm, " << deg << " deg\n";
    EXPECT_LE(mm, kPoseBoundMm);
    EXPECT_LE(deg, kAngleBoundDeg);
    // The same points judged under the true placement.
    auto truth = Inspect(s, Plan(json()), cell_->world_from_part * part.in_fixture);
    ASSERT_TRUE(truth.ok()) << truth.status();
    for (const std::string name : {"surface", "ridge"}) {
      EXPECT_NEAR(Named(*rps, name).mean_mm, Named(*truth, name).mean_mm, 0.005) << name;
      EXPECT_NEAR(Named(*rps, name).rms_mm, Named(*truth, name).rms_mm, 0.005) << name;
    }
    EXPECT_EQ(rps->plan.pass(), truth->plan.pass());
  }
}

TEST_F(InspectionAlignment, ABentRidgeStillFailsAfterRpsWhileAWholePartBestFitHidesPartOfIt) {
  DemoPart part;
  part.number = 41;
  std::mt19937_64 rng(41);
  part.in_fixture = RandomFixture(rng);
  // The ridge bent up by 0.3 mm, over ~140 mm of its length (the RPS
  // surface points see less than 0.03 mm of it).
  const double x = 5, z = PillarRidgeZ(x, cell_->part_length_mm);
  part.defects = {{{x, 0, z}, 70, -0.3}};
  const testing::ScannedPart s = testing::ScanDemoPart(*cell_, part, 41);
  auto rps = Inspect(s, Plan(Rps()), cell_->world_from_part);
  ASSERT_TRUE(rps.ok()) << rps.status();
  ASSERT_TRUE(rps->plan.alignment.ok()) << rps->plan.alignment.failure;
  const CharacteristicResult& ridge = Named(*rps, "ridge");
  EXPECT_FALSE(ridge.pass);
  EXPECT_GT(ridge.max_mm, 0.25);
  EXPECT_FALSE(rps->plan.pass());
  auto fit = Inspect(s, Plan({{"mode", "best_fit"}}), cell_->world_from_part);
  ASSERT_TRUE(fit.ok()) << fit.status();
  ASSERT_TRUE(fit->plan.alignment.aligned) << fit->plan.alignment.failure;
  // The robust kernel (Tukey's) gives the bend's core no weight, so the
  // fit leans only on its tails (the test prints both peaks). A
  // least-squares fit would lean far more.
  EXPECT_LT(Named(*fit, "ridge").max_mm, ridge.max_mm - 0.002) << "the fit leans into the bend";
  EXPECT_NE(fit->plan.alignment.note.find("whole part"), std::string::npos);
  std::cout << "ridge peak after RPS " << ridge.max_mm << " mm, after a whole-part best-fit "
            << Named(*fit, "ridge").max_mm << " mm\n";
}

TEST_F(InspectionAlignment, LockedDegreesOfFreedomStayExactlyZero) {
  DemoPart part;
  part.number = 51;
  std::mt19937_64 rng(51);
  part.in_fixture = RandomFixture(rng);
  const testing::ScannedPart s = testing::ScanDemoPart(*cell_, part, 51);
  auto fit = Inspect(s, Plan({{"mode", "best_fit"}, {"locked", {"tz", "rx", "ry"}}}),
                     cell_->world_from_part);
  ASSERT_TRUE(fit.ok()) << fit.status();
  const AlignmentOutcome& a = fit->plan.alignment;
  ASSERT_TRUE(a.aligned) << a.failure;
  EXPECT_EQ(a.dofs, 3);
  EXPECT_EQ(a.x[kTz], 0.0);
  EXPECT_EQ(a.x[kRx], 0.0);
  EXPECT_EQ(a.x[kRy], 0.0);
  EXPECT_EQ(a.correction.translation().z(), 0.0);
  // The free ones moved: the displacement has x, y and a turn about z.
  EXPECT_GT(std::abs(a.x[kTx]) + std::abs(a.x[kTy]), 0.01);
  const json report = EncodeReport(MakeInspectionReport(fit->error_map, {}, fit->plan));
  EXPECT_EQ(report["alignment"]["locked"], json({"tz", "rx", "ry"}));
  EXPECT_EQ(report["alignment"]["mode"], "best_fit");
}

TEST_F(InspectionAlignment, ACorrectionBeyondTheAllowedMaximumFailsThePart) {
  DemoPart part;
  part.number = 61;
  part.in_fixture = Eigen::Translation3d(0.8, 0, 0) * Eigen::Isometry3d::Identity();
  const testing::ScannedPart s = testing::ScanDemoPart(*cell_, part, 61);
  json rps = Rps();
  rps["max_correction_mm"] = 0.5;
  auto r = Inspect(s, Plan(rps), cell_->world_from_part);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_TRUE(r->plan.alignment.aligned);
  EXPECT_FALSE(r->plan.alignment.within_max_correction);
  EXPECT_NEAR(r->plan.alignment.correction_mm, 0.8, 0.05);
  EXPECT_FALSE(r->plan.pass());
  EXPECT_NE(r->plan.characteristics.reason.find("more than the 0.5 mm"), std::string::npos)
      << r->plan.characteristics.reason;
  const json report = EncodeReport(MakeInspectionReport(r->error_map, {}, r->plan));
  EXPECT_EQ(report["verdict"], "fail");
  EXPECT_EQ(report["alignment"]["within_max_correction"], false);
}

TEST_F(InspectionAlignment, CalibratedPlansWriteNoAlignmentBlock) {
  DemoPart part;
  const testing::ScannedPart s = testing::ScanDemoPart(*cell_, part, 71);
  auto r = Inspect(s, Plan(json()), cell_->world_from_part);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(r->plan.alignment.mode, AlignmentMode::kCalibrated);
  const json report = EncodeReport(MakeInspectionReport(r->error_map, {}, r->plan));
  EXPECT_FALSE(report.contains("alignment"));
}

}  // namespace
}  // namespace surfinspect
