#include "core/simulation/demo_cell.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <filesystem>

#include "core/io/io_point_cloud.h"
#include "core/plan/cad_holes.h"
#include "core/plan/inspection_plan.h"
#include "core/types/transform.h"
#include "tests/support/temp_dir.h"

namespace surfinspect {
namespace {

TEST(DemoCell, PillarIsAnOpenSheetWithOutwardNormalsAndAFewThousandTriangles) {
  const TriangleMesh part = MakePillarMesh(300);
  ASSERT_TRUE(part.Validate().ok());
  EXPECT_GT(part.num_triangles(), 2000u);
  EXPECT_LT(part.num_triangles(), 10000u);
  EXPECT_EQ(part.CountDegenerate(), 0u);
  const MeshTopology topo = AnalyzeTopology(part);
  EXPECT_GT(topo.boundary_edges, 0u);  // sheet metal: an open surface
  EXPECT_EQ(topo.nonmanifold_edges, 0u);
  const Bounds3 b = ComputeBounds(part);
  EXPECT_NEAR(b.max.x() - b.min.x(), 300.0, 1e-3);
  // Every facet's normal points away from the channel's inside: up on the
  // ridge, outwards on the walls, up on the flanges (never down).
  const auto normals = part.FaceNormals();
  for (const auto& n : normals) EXPECT_GT(n.z(), -1e-6);
}

TEST(DemoCell, GaugeIsClosedAndPinsSixDof) {
  const TriangleMesh gauge = MakeGaugeMesh();
  ASSERT_TRUE(gauge.Validate().ok());
  EXPECT_TRUE(AnalyzeTopology(gauge).closed());
  // Face-normal scatter matrix (area-weighted) has full rank: translations
  // are constrained in x, y and z.
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  const auto normals = gauge.FaceNormals();
  for (const auto& n : normals) scatter += n.cast<double>() * n.cast<double>().transpose();
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvalues().minCoeff(), 1.0);
}

TEST(DemoCell, FiveViewpointsSeeTheRidgeAndTheirGauges) {
  const DemoCell cell = MakeDemoCell();
  ASSERT_EQ(cell.viewpoints.size(), 5u);
  for (const auto& vp : cell.viewpoints) {
    const PoseDifference off = ComparePoses(vp.world_from_sensor, vp.nominal_world_from_sensor);
    EXPECT_NEAR(off.translation_mm, 3.0, 1e-9);
    EXPECT_NEAR(off.rotation_deg, 2.0, 1e-9);
    auto part_scan =
        SimulateScan(cell.part, cell.world_from_part, vp.world_from_sensor, cell.intrinsics, {});
    auto gauge_scan =
        SimulateScan(cell.gauge, vp.world_from_gauge, vp.world_from_sensor, cell.intrinsics, {});
    ASSERT_TRUE(part_scan.ok() && gauge_scan.ok());
    EXPECT_GT(part_scan->hits, 200000u) << vp.name;
    EXPECT_GT(gauge_scan->hits, 150000u) << vp.name;
    // The sensor is ~400 mm above what it looks at.
    const Bounds3 b = ComputeBounds(part_scan->cloud_in_sensor);
    EXPECT_GT(b.min.z(), 300.0);
    EXPECT_LT(b.max.z(), 520.0);
  }
}

// The demo's RPS set names two round holes of the top and locks all six
// degrees of freedom on the demo part (its plan validates).
TEST(DemoCell, TheRpsAlignmentLocksTheDemoPart) {
  const DemoCell cell = MakeDemoCell();
  const nlohmann::json a = DemoRpsAlignment(cell);
  ASSERT_EQ(a["references"].size(), 6u);
  const nlohmann::json holes = PlanHolesJson(ListHoles(cell.part), 0.3);
  nlohmann::json plan = {{"holes", holes["holes"]}, {"slots", holes["slots"]}, {"alignment", a}};
  auto parsed = ParseInspectionPlan(plan, cell.part);
  ASSERT_TRUE(parsed.ok()) << parsed.status();
  for (int k : {0, 1}) {
    const std::string name = a["references"][k]["hole"];
    const auto it = std::find_if(parsed->holes.begin(), parsed->holes.end(),
                                 [&](const PlanHole& h) { return h.name == name; });
    ASSERT_NE(it, parsed->holes.end());
    EXPECT_GT(it->position_mm.z(), 50) << name << " lies on the top";
  }
}

}  // namespace
}  // namespace surfinspect
