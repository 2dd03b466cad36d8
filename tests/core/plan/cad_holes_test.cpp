// The CAD hole lister against the pillar the holes were cut in.
#include "core/plan/cad_holes.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "core/simulation/pillar.h"

namespace surfinspect {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

// The lister finds exactly the holes that were cut, at their places.
TEST(CadHoles, ThePillarsHolesAreListedWhereTheyWereCut) {
  const PillarFeatures features = DemoPillarFeatures();
  const TriangleMesh part = MakePillarMesh(300, features);
  const std::vector<CadHole> holes = ListHoles(part);
  ASSERT_EQ(holes.size(), features.holes.size());
  for (const PillarHole& h : features.holes) {
    const CadHole* found = nullptr;
    for (const CadHole& c : holes)
      if (std::hypot(c.position_mm.x() - h.x_mm, c.position_mm.y() - h.y_mm) < 0.01) found = &c;
    ASSERT_NE(found, nullptr) << "hole at " << h.x_mm << ", " << h.y_mm;
    EXPECT_EQ(found->slot, h.length_mm > 0);
    // Cut along z in a face that sags by up to 2 degrees: the edge is
    // longer along x by up to 1/cos(2 deg) in the face's plane.
    EXPECT_NEAR(found->diameter_mm, h.diameter_mm, 0.005);
    if (found->slot) {
      EXPECT_NEAR(found->length_mm, h.length_mm, 0.008);
      EXPECT_GT(std::abs(found->direction.x()), 0.999);
    }
    EXPECT_GT(found->axis.z(), 0.99) << "the side the face looks to";
    EXPECT_NEAR(
        found->position_mm.z(),
        (std::abs(h.y_mm) < 30 ? PillarRidgeZ(h.x_mm, 300) : PillarRidgeZ(h.x_mm, 300) - 60), 0.02);
  }
  EXPECT_TRUE(ListHoles(MakePillarMesh(300)).empty()) << "the outer boundary is not a hole";
}

TEST(CadHoles, APlaneFrameIsRightHandedAndFollowsTheSlot) {
  const PlaneFrame f = MakePlaneFrame({1, 2, 3}, {0, 0, 2}, {1, 1, 5});
  EXPECT_NEAR((f.e1 - Vector3d(1, 1, 0).normalized()).norm(), 0, 1e-12);
  EXPECT_NEAR((f.e1.cross(f.e2) - f.axis).norm(), 0, 1e-12);
  const Vector3d p(4, -1, 7);
  const Vector2d q = f.To2d(p);
  EXPECT_NEAR((f.To3d(q) - (p - 4 * Vector3d::UnitZ())).norm(), 0, 1e-12) << "drops the height";
  const PlaneFrame g = MakePlaneFrame({0, 0, 0}, {0, 0, 1});  // no direction: a fixed choice
  EXPECT_NEAR(std::abs(g.e1.dot(g.axis)), 0, 1e-12);
}

}  // namespace
}  // namespace surfinspect
