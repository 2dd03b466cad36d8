// Holes made off their CAD: the lister finds them where they were moved,
// as large as they were made.
#include "core/simulation/hole_changes.h"

#include <gtest/gtest.h>

#include "core/plan/cad_holes.h"
#include "core/simulation/pillar.h"

namespace surfinspect {
namespace {

TEST(HoleChanges, AMovedAndGrownHoleIsListedWhereAndAsLargeAsItWasMade) {
  const TriangleMesh cad = MakePillarMesh(300, DemoPillarFeatures());
  const std::vector<CadHole> before = ListHoles(cad);
  std::size_t slot = before.size();
  for (std::size_t k = 0; k < before.size(); ++k)
    if (before[k].slot) slot = k;
  ASSERT_LT(slot, before.size());
  const Eigen::Vector3d along_axis = 5 * before[0].axis;  // dropped
  auto made = ChangeHoles(
      cad, {{0, Eigen::Vector3d(0.3, -0.2, 0) + along_axis, 0.2}, {slot, {0, 0, 0}, -0.15}});
  ASSERT_TRUE(made.ok()) << made.status();
  const std::vector<CadHole> after = ListHoles(*made);
  ASSERT_EQ(after.size(), before.size());
  const Eigen::Vector3d moved = after[0].position_mm - before[0].position_mm;
  EXPECT_NEAR(moved.x(), 0.3, 0.01);
  EXPECT_NEAR(moved.y(), -0.2, 1e-4);
  EXPECT_NEAR(after[0].diameter_mm - before[0].diameter_mm, 0.2, 1e-4);
  EXPECT_NEAR(after[slot].diameter_mm - before[slot].diameter_mm, -0.15, 1e-4);
  EXPECT_NEAR(after[slot].length_mm - before[slot].length_mm, -0.15, 1e-4);
  for (std::size_t k = 1; k < after.size(); ++k) {
    if (k == slot) continue;
    EXPECT_LT((after[k].position_mm - before[k].position_mm).norm(), 1e-6) << k;
    EXPECT_EQ(after[k].diameter_mm, before[k].diameter_mm) << k;
  }
  EXPECT_EQ(ChangeHoles(cad, {{before.size(), {0, 0, 0}, 0}}).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace surfinspect
