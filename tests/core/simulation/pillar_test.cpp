// The pillar with its features: holes cut without folds, the trim offset
// and the walls where they were asked for.
#include "core/simulation/pillar.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

namespace surfinspect {
namespace {

using Eigen::Vector3d;

// Sums of the triangles' xy-projected areas: signed and absolute.
std::pair<double, double> ProjectedAreas(const TriangleMesh& part) {
  double signed_area = 0, area = 0;
  for (const Triangle& t : part.triangles) {
    const Vector3d a = part.vertices[t[0]].cast<double>(), b = part.vertices[t[1]].cast<double>(),
                   c = part.vertices[t[2]].cast<double>();
    const double z = (b - a).cross(c - a).z() / 2;
    signed_area += z;
    area += std::abs(z);
  }
  return {signed_area, area};
}

// The pillar is a height field over xy: a triangulation without folds
// covers each point of its footprint once, so the projected areas sum to
// their signed sum (which Green's theorem fixes by the boundary alone,
// folded or not), and that is the footprint less the holes.
TEST(Pillar, HolesAreCutWithoutFolds) {
  const auto [plain_signed, plain] = ProjectedAreas(MakePillarMesh(300));
  EXPECT_NEAR(plain, plain_signed, 1e-9 * plain);
  const PillarFeatures features = DemoPillarFeatures();
  const auto [signed_area, area] = ProjectedAreas(MakePillarMesh(300, features));
  EXPECT_NEAR(area, signed_area, 1e-6 * area);
  double holes = 0;  // 96-gons: (n/2) r^2 sin(2 pi / n), a slot's middle 2 h w more
  for (const PillarHole& h : features.holes) {
    const double r = h.diameter_mm / 2;
    holes +=
        48 * r * r * std::sin(2 * M_PI / 96) + std::max(h.length_mm - h.diameter_mm, 0.0) * 2 * r;
  }
  EXPECT_NEAR(plain_signed - signed_area, holes, 0.05);
}

TEST(Pillar, TheTrimMovesTheEndAndWallsHangBelowTheHoles) {
  const TriangleMesh plain = MakePillarMesh(300);
  PillarFeatures f;
  f.trim_offset_mm = 0.4;
  const TriangleMesh trimmed = MakePillarMesh(300, f);
  double x_plain = -INFINITY, x_trimmed = -INFINITY;
  for (const auto& v : plain.vertices) x_plain = std::max(x_plain, double(v.x()));
  for (const auto& v : trimmed.vertices) x_trimmed = std::max(x_trimmed, double(v.x()));
  EXPECT_NEAR(x_trimmed - x_plain, 0.4, 1e-5);

  f = {};
  f.holes = {{0, 0, 8, 0}};
  const TriangleMesh open = MakePillarMesh(300, f);
  f.wall_depth_mm = 1.5;
  const TriangleMesh walled = MakePillarMesh(300, f);
  EXPECT_EQ(walled.triangles.size(), open.triangles.size() + 2 * 96);
  EXPECT_EQ(walled.vertices.size(), open.vertices.size() + 96);
  for (std::size_t v = open.vertices.size(); v < walled.vertices.size(); ++v)
    EXPECT_NEAR(walled.vertices[v].z(), PillarRidgeZ(walled.vertices[v].x(), 300) - 1.5, 0.01);

  f = {};
  f.holes = {{0, 40, 8, 0}};  // on the wall's bend: no flat face holds it
  EXPECT_EQ(MakePillarMesh(300, f).triangles.size(), plain.triangles.size());
}

}  // namespace
}  // namespace surfinspect
