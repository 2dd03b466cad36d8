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

// A washer as a closed solid (outward normals): 48 segments, bore 8 mm,
// outside 20 mm, 3 mm thick.
TriangleMesh Washer() {
  constexpr int n = 48;
  constexpr double r_in = 4, r_out = 10, h = 3;
  TriangleMesh m;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n, c = std::cos(a), s = std::sin(a);
    for (const auto& [r, z] : {std::pair{r_in, h}, {r_out, h}, {r_in, 0.0}, {r_out, 0.0}})
      m.vertices.emplace_back(float(r * c), float(r * s), float(z));
  }
  // Per segment: inner top, outer top, inner bottom, outer bottom.
  const auto it = [](int i) { return uint32_t(4 * (i % n)); };
  const auto ot = [&](int i) { return it(i) + 1; };
  const auto ib = [&](int i) { return it(i) + 2; };
  const auto ob = [&](int i) { return it(i) + 3; };
  for (int i = 0; i < n; ++i) {
    const int j = i + 1;
    m.triangles.push_back({it(i), ot(i), ot(j)});  // top, +z
    m.triangles.push_back({it(i), ot(j), it(j)});
    m.triangles.push_back({ib(i), ob(j), ob(i)});  // bottom, -z
    m.triangles.push_back({ib(i), ib(j), ob(j)});
    m.triangles.push_back({ob(i), ob(j), ot(j)});  // outside wall, away from the axis
    m.triangles.push_back({ob(i), ot(j), ot(i)});
    m.triangles.push_back({ib(i), it(j), ib(j)});  // bore wall, towards the axis
    m.triangles.push_back({ib(i), it(i), it(j)});
  }
  return m;
}

// A closed solid has no boundary: its bore is found by its two rims, each
// with the axis its face looks to; the outside rims are a boss's (the wall
// faces away from the axis) and are not holes.
TEST(CadHoles, ASolidsBoreIsListedAtBothRimsAndItsOutsideIsNot) {
  const std::vector<CadHole> holes = ListHoles(Washer());
  ASSERT_EQ(holes.size(), 2u);
  for (const CadHole& h : holes) {
    EXPECT_TRUE(h.rim);
    EXPECT_FALSE(h.slot);
    EXPECT_NEAR(h.diameter_mm, 8.0, 1e-5);
    EXPECT_NEAR(h.position_mm.head<2>().norm(), 0.0, 1e-5);
  }
  // Sorted by position: the bottom rim (z = 0, looking down), then the top.
  EXPECT_NEAR(holes[0].position_mm.z(), 0.0, 1e-6);
  EXPECT_NEAR(holes[0].axis.z(), -1.0, 1e-9);
  EXPECT_NEAR(holes[1].position_mm.z(), 3.0, 1e-6);
  EXPECT_NEAR(holes[1].axis.z(), 1.0, 1e-9);
}

}  // namespace
}  // namespace surfinspect
