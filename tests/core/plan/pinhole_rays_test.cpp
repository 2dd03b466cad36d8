// Pixel rays fitted from an organized cloud, against the simulator's own
// pinhole (core/simulation/scan_simulator.cpp: the ray of pixel (c, r)
// passes through ((c + 0.5 - w/2) / f, (r + 0.5 - h/2) / f, 1)).
#include "core/plan/pinhole_rays.h"

#include <gtest/gtest.h>

#include "core/simulation/demo_cell.h"

namespace surfinspect {
namespace {

TEST(PinholeRays, TheSimulatorsRaysAreRecoveredFromItsNoisyCloud) {
  const DemoCell cell = MakeDemoCell();
  ScanOptions opt;
  opt.noise_sigma_mm = 0.015;  // along the ray: x/z and y/z keep their values
  auto scan = SimulateDemoPartScan(cell, DemoPart{}, 2, opt);
  ASSERT_TRUE(scan.ok()) << scan.status();
  auto rays = FitPinholeRays(scan->cloud_in_sensor);
  ASSERT_TRUE(rays.ok()) << rays.status();
  EXPECT_LT(rays->rms_px, 0.01);
  const double f = FocalLengthPixels(cell.intrinsics);
  const double w = cell.intrinsics.width, h = cell.intrinsics.height;
  for (const auto& [col, row] : {std::pair<double, double>{0, 0}, {1023, 767}, {500, 10}}) {
    const Eigen::Vector3d d = rays->Direction(col, row);
    EXPECT_NEAR(d.x() / d.z(), (col + 0.5 - w / 2) / f, 1e-6) << col << ", " << row;
    EXPECT_NEAR(d.y() / d.z(), (row + 0.5 - h / 2) / f, 1e-6) << col << ", " << row;
    EXPECT_GT(d.z(), 0) << "towards the scene";
    Eigen::Vector2d px;
    ASSERT_TRUE(ProjectToPixel(*rays, 400 * d, &px));
    EXPECT_NEAR(px.x(), col, 1e-6);
    EXPECT_NEAR(px.y(), row, 1e-6);
  }
  EXPECT_FALSE(ProjectToPixel(*rays, {0, 0, -1}, nullptr)) << "behind the sensor";
}

TEST(PinholeRays, CloudsThatAreNoPinholesAreRefused) {
  EXPECT_EQ(FitPinholeRays(PointCloud::Unorganized({{0, 0, 1}})).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(FitPinholeRays(PointCloud::Organized(64, 48)).status().code(),
            absl::StatusCode::kInvalidArgument)
      << "no valid point";
  PointCloud grid = PointCloud::Organized(64, 48);  // x/z grows with the row: no pinhole
  for (uint32_t r = 0; r < 48; ++r)
    for (uint32_t c = 0; c < 64; ++c)
      grid.points[r * 64 + c] = {float(c % 7) * 3.0f, float(r), 100.0f};
  EXPECT_EQ(FitPinholeRays(grid).status().code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace surfinspect
