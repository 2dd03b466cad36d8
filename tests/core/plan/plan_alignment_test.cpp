// The plan's alignment block (core/plan/plan_alignment.cpp, read through
// core/plan/plan_json_read.cpp): its JSON form round trip, the directions
// each RPS reference locks, and the refusals that name the field, among
// them RPS sets that leave motions free (named).
#include "core/plan/plan_alignment.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "core/plan/cad_holes.h"
#include "core/simulation/pillar.h"

namespace surfinspect {
namespace {

using nlohmann::json;

class PlanAlignmentTest : public ::testing::Test {
 protected:
  void SetUp() override {
    features_.holes = {{-110, 0, 8, 0}, {35, 10, 10, 0}, {95, -8, 6, 14}};
    part_ = MakePillarMesh(300, features_);
    const json holes = PlanHolesJson(ListHoles(part_), 0.3);
    plan_ = {{"holes", holes["holes"]}, {"slots", holes["slots"]}};
    for (const json& h : holes["holes"])
      (h["position_mm"][0].get<double>() < 0 ? left_ : right_) = h["name"];
    slot_ = holes["slots"][0]["name"];
  }
  json Top(double x, double y) const { return {x, y, PillarRidgeZ(x, 300)}; }
  json Flange(double x, double y) const { return {x, y, PillarRidgeZ(x, 300) - 60}; }
  absl::StatusOr<InspectionPlan> Parse(const json& alignment) const {
    json p = plan_;
    p["alignment"] = alignment;
    return ParseInspectionPlan(p, part_);
  }
  json Rps(json refs) const { return {{"mode", "rps"}, {"references", std::move(refs)}}; }
  json Surface(const std::string& name, const json& at) const {
    return {{"name", name}, {"position_mm", at}};
  }

  PillarFeatures features_;
  TriangleMesh part_;
  json plan_;
  std::string left_, right_, slot_;
};

TEST_F(PlanAlignmentTest, TwoHolesAndFourSurfacePointsLockEverything) {
  auto plan = Parse(Rps({{{"name", "A1"}, {"hole", left_}},
                         {{"name", "A2"}, {"hole", right_}},
                         Surface("B1", Top(-70, 15)),
                         Surface("B2", Top(120, -15)),
                         Surface("C1", Flange(-120, 65)),
                         Surface("C2", Flange(120, -65))}));
  ASSERT_TRUE(plan.ok()) << plan.status();
  const std::vector<RpsReference> refs = NominalRpsReferences(*plan, part_);
  ASSERT_EQ(refs.size(), 6u);
  for (int k : {0, 1}) {  // a hole locks the two directions of its plane
    ASSERT_EQ(refs[k].directions.size(), 2u);
    const PlanHole& h = plan->holes[k == 0 ? 0 : 1];
    const PlanHole& hole = h.name == plan->alignment.references[k].hole ? h : plan->holes[1 - k];
    for (const auto& d : refs[k].directions) EXPECT_NEAR(d.dot(hole.axis), 0, 1e-12);
    EXPECT_NEAR(refs[k].directions[0].dot(refs[k].directions[1]), 0, 1e-12);
    EXPECT_EQ(refs[k].nominal_mm, hole.position_mm);
  }
  for (int k : {2, 3, 4, 5}) {  // a surface point its CAD normal, on the CAD
    ASSERT_EQ(refs[k].directions.size(), 1u);
    EXPECT_GT(refs[k].directions[0].z(), 0.99);
    EXPECT_NEAR(refs[k].nominal_mm.z(), plan->alignment.references[k].position_mm.z(), 0.05);
  }
  // The JSON form round trips.
  auto again = Parse(PlanAlignmentJson(plan->alignment));
  ASSERT_TRUE(again.ok()) << again.status();
  EXPECT_EQ(PlanAlignmentJson(again->alignment), PlanAlignmentJson(plan->alignment));
}

TEST_F(PlanAlignmentTest, ASlotLocksOnlyTheDirectionAcrossIt) {
  auto plan = Parse(Rps({{{"name", "S"}, {"hole", slot_}},
                         {{"name", "A"}, {"hole", left_}},
                         Surface("B1", Top(-70, 15)),
                         Surface("B2", Top(60, -15)),
                         Surface("C1", Flange(0, 65))}));
  ASSERT_TRUE(plan.ok()) << plan.status();
  const RpsReference slot = NominalRpsReferences(*plan, part_)[0];
  ASSERT_EQ(slot.directions.size(), 1u);
  EXPECT_NEAR(std::abs(slot.directions[0].y()), 1, 1e-9);  // the slot runs along x
}

TEST_F(PlanAlignmentTest, SetsThatLeaveMotionsFreeAreRefusedNamingThem) {
  // Three surface points on a line of the top and one hole: the hole
  // holds x and y, the points z and the tilt about y; free: about x and z.
  auto collinear = Parse(Rps({{{"name", "A"}, {"hole", left_}},
                              Surface("B1", Top(-60, 0)),
                              Surface("B2", Top(0, 0)),
                              Surface("B3", Top(60, 0))}));
  ASSERT_FALSE(collinear.ok());
  EXPECT_NE(collinear.status().message().find("plan.alignment.references"), std::string::npos);
  EXPECT_NE(collinear.status().message().find("leave free"), std::string::npos)
      << collinear.status().message();
  EXPECT_NE(collinear.status().message().find("rotation about"), std::string::npos);
  auto one_hole = Parse(Rps({{{"name", "A"}, {"hole", left_}}}));
  ASSERT_FALSE(one_hole.ok());
  EXPECT_NE(one_hole.status().message().find("leave free"), std::string::npos);
}

TEST_F(PlanAlignmentTest, BadBlocksAreRefusedNamingTheField) {
  const auto message = [&](const json& a) {
    auto p = Parse(a);
    return p.ok() ? std::string("accepted") : std::string(p.status().message());
  };
  EXPECT_EQ(message({{"mode", "wobble"}}),
            "plan.alignment.mode: must be calibrated, rps or best_fit");
  EXPECT_EQ(message({{"mode", "rps"}}), "plan.alignment.references: mode rps needs references");
  EXPECT_EQ(message(Rps({{{"name", "A"}, {"hole", "H99"}}})),
            "plan.alignment.references[0].hole: no hole or slot \"H99\" in the plan");
  EXPECT_EQ(message(Rps({{{"name", "A"}, {"hole", left_}, {"position_mm", {0, 0, 0}}}})),
            "plan.alignment.references[0]: needs exactly one of hole (a plan hole or slot) and "
            "position_mm");
  EXPECT_EQ(message({{"mode", "best_fit"}, {"locked", {"tx", "ty", "tz", "rx", "ry", "rz"}}}),
            "plan.alignment.locked: locks all six degrees of freedom");
  EXPECT_EQ(message({{"mode", "best_fit"}, {"locked", {"up"}}}),
            "plan.alignment.locked[0]: must be one of tx, ty, tz, rx, ry, rz");
  EXPECT_EQ(message({{"mode", "best_fit"}, {"regions", {"nowhere"}}}),
            "plan.alignment.regions[0]: no region \"nowhere\" in the plan");
  EXPECT_EQ(message({{"mode", "calibrated"}, {"regions", {"x"}}}),
            "plan.alignment.regions: only for mode best_fit");
  EXPECT_EQ(message({{"mode", "best_fit"}, {"max_correction_mm", -1}}),
            "plan.alignment.max_correction_mm: must be > 0");
  EXPECT_EQ(message({{"mode", "best_fit"}, {"stiff", true}}), "plan.alignment.stiff: unknown key");
  EXPECT_EQ(message({{"mode", "best_fit"}, {"locked", {"rz"}}}), "accepted");
}

}  // namespace
}  // namespace surfinspect
