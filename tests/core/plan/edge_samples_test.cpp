// The edge sampler on its own: a flat plate seen straight on by an ideal
// pinhole, its edge at a known place between pixel rays; the samples lie
// within half a ray step of it and average to it.
#include "core/plan/edge_samples.h"

#include <gtest/gtest.h>

namespace surfinspect {
namespace {

// A 200 x 150 grid of a plate z = 300 mm covering x < edge (sensor frame:
// the sensor at the origin looking along +z), 0.25 mm per pixel there.
PointCloud Plate(double edge_x) {
  PointCloud g = PointCloud::Organized(200, 150);
  for (uint32_t r = 0; r < 150; ++r)
    for (uint32_t c = 0; c < 200; ++c) {
      const double a = (c - 99.5) / 1200.0, b = (r - 74.5) / 1200.0;  // f = 1200 px
      if (300 * a < edge_x)
        g.points[r * 200 + c] = Eigen::Vector3d(300 * a, 300 * b, 300).cast<float>();
    }
  return g;
}

TEST(EdgeSamples, AStraightEdgeBetweenRaysIsSampledAtItsMidpoints) {
  const double edge_x = 1.03;  // between the rays at 0.875 and 1.125 mm
  const PointCloud grid = Plate(edge_x);
  const std::vector<PlanView> views = {{"v", &grid, Eigen::Isometry3d::Identity()}};
  const std::vector<RayView> rays = PrepareRayViews(views);
  ASSERT_EQ(rays.size(), 1u);
  EdgeContour c;
  // The plate's face: normal -z (towards the sensor), e1 along y; the
  // material lies at x < 1.0 (the nominal edge), so + into it is -x.
  c.frame = MakePlaneFrame({1.0, 0, 300}, {0, 0, -1}, {0, 1, 0});
  const double sign = c.frame.e2.x() > 0 ? -1.0 : 1.0;
  c.into_material = [sign](const Eigen::Vector2d& q) { return sign * q.y(); };
  for (double u : {-8.0, 8.0})
    for (double v : {-5.0, 5.0}) c.outline.emplace_back(u, v);
  const EdgeSamples s = SampleEdge(rays, c, {});
  ASSERT_GT(s.points.size(), 50u);
  EXPECT_EQ(s.wall, 0u);
  EXPECT_EQ(s.views, 1u);
  EXPECT_NEAR(s.PixelPitch(), 0.25, 1e-6);
  for (const Eigen::Vector2d& q : s.points)
    EXPECT_NEAR(-c.into_material(q), 0.0, 1e-6) << "the midpoint of the rays at 0.875 and 1.125";
}

}  // namespace
}  // namespace surfinspect
