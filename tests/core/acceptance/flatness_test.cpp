// core/acceptance/flatness.cpp: F of a sampled plate with a planted boss,
// the disc selection, and a plate scan with too few points.
#include "core/acceptance/flatness.h"

#include <gtest/gtest.h>

namespace surfinspect {
namespace {

PointCloud Plate(double step, int pitch) {
  std::vector<Eigen::Vector3f> pts;
  const Eigen::Vector3d n = Eigen::Vector3d(0, 0.05, 1).normalized();
  const Eigen::Vector3d a = n.unitOrthogonal(), b = n.cross(a);
  for (int i = -70; i <= 70; i += pitch)
    for (int j = -70; j <= 70; j += pitch) {
      const double h = i * i + j * j <= 100 ? step : 0.0;  // a centred boss
      pts.push_back((Eigen::Vector3d(0, 0, 40) + i * a + j * b + h * n).cast<float>());
    }
  pts.emplace_back(0, 0, 50);  // 10 mm above: outside the search band
  return PointCloud::Unorganized(std::move(pts));
}

TEST(Flatness, PlantedBossIsTheRange) {
  PlaneSearch s;
  s.centre_hint_mm = {0, 0, 40.5};
  s.normal_hint = Eigen::Vector3d(0, 0.05, 1).normalized();
  s.radius_mm = 50;
  auto flat = MeasureFlatness(Plate(0, 1), s, 0, "plate-1");
  ASSERT_TRUE(flat.ok()) << flat.status();
  EXPECT_LT(flat->f_mm, 1e-5);
  auto stepped = MeasureFlatness(Plate(0.004, 1), s, 0, "plate-1");
  ASSERT_TRUE(stepped.ok());
  EXPECT_NEAR(stepped->f_mm, 0.004, 1e-5);  // symmetric: the LS plane does not tilt
  EXPECT_LE(stepped->kept, std::size_t(M_PI * 51 * 51));
}

TEST(Flatness, TooFewPlatePointsIsAClearError) {
  PlaneSearch s;
  s.centre_hint_mm = {0, 0, 40};
  s.radius_mm = 50;
  auto f = MeasureFlatness(Plate(0, 10), s, 0.003, "plate-1");  // ~80 points in the disc
  ASSERT_EQ(f.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(f.status().message().find("plate-1"), std::string::npos);
  EXPECT_NE(f.status().message().find("at least 200 needed"), std::string::npos);
}

}  // namespace
}  // namespace surfinspect
