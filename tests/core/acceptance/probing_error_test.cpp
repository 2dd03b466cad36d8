// core/acceptance/probing_error.cpp: PF and PS of a sampled sphere with a
// planted form error and size, the trimmed range, and a sphere that is not
// in the scan.
#include "core/acceptance/probing_error.h"

#include <gtest/gtest.h>

#include <random>

namespace surfinspect {
namespace {

// A hemisphere cap of radius r about c plus a flat floor 20 mm below; the
// cap carries a radial bump of `bump` mm along +x.
PointCloud Scene(const Eigen::Vector3d& c, double r, double bump) {
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i <= 60; ++i)
    for (int k = 0; k < 120; ++k) {
      const double polar = M_PI / 2 * i / 60, az = 2 * M_PI * k / 120;
      const Eigen::Vector3d n(std::sin(polar) * std::cos(az), std::sin(polar) * std::sin(az),
                              std::cos(polar));
      const double dr = n.x() > 0.95 ? bump : 0.0;
      pts.push_back((c + (r + dr) * n).cast<float>());
    }
  for (int x = -60; x <= 60; x += 2)
    for (int y = -60; y <= 60; y += 2)
      pts.push_back((c + Eigen::Vector3d(x, y, -20)).cast<float>());
  return PointCloud::Unorganized(std::move(pts));
}

TEST(ProbingError, PlantedSizeAndFormComeBack) {
  const Eigen::Vector3d c(600, 100, 55);
  SphereSearch s;
  s.centre_hint_mm = c + Eigen::Vector3d(1, -1, 0.5);
  s.diameter_mm = 25.0;
  auto clean = MeasureSphere(Scene(c, 12.503, 0), s, 0.0, "sphere-1");
  ASSERT_TRUE(clean.ok()) << clean.status();
  EXPECT_NEAR(clean->ps_mm, 0.006, 1e-5);  // float coordinates at 600 mm: ~4e-5 mm
  EXPECT_NEAR(clean->pf_mm, 0.0, 1e-4);
  EXPECT_LT((clean->fit.centre - c).norm(), 1e-5);
  // A 10 µm bump on a small patch: PF sees (nearly) all of it.
  auto bumped = MeasureSphere(Scene(c, 12.5, 0.010), s, 0.0, "sphere-1");
  ASSERT_TRUE(bumped.ok());
  EXPECT_NEAR(bumped->pf_mm, 0.010, 0.001);
  // Leaving out a share larger than the bump's points hides it.
  auto trimmed = MeasureSphere(Scene(c, 12.5, 0.010), s, 0.04, "sphere-1");
  ASSERT_TRUE(trimmed.ok());
  EXPECT_LT(trimmed->pf_mm, 0.002);
  EXPECT_GT(trimmed->left_out, 0u);
}

TEST(ProbingError, TrimmedRangeLeavesOutTheLargestAbsoluteResiduals) {
  std::size_t lo = 0, hi = 0, out = 0;
  const std::vector<double> r = {0.1, -0.2, 5.0, 0.3, -0.1, -4.0, 0.0, 0.2, 0.1, -0.3};
  EXPECT_DOUBLE_EQ(TrimmedRange(r, 0.0, &lo, &hi, &out), 9.0);
  EXPECT_DOUBLE_EQ(TrimmedRange(r, 0.2, &lo, &hi, &out), 0.6);
  EXPECT_EQ(out, 2u);
  EXPECT_EQ(hi, 3u);
  EXPECT_EQ(lo, 9u);
}

TEST(ProbingError, ASphereNotInTheScanIsNotFound) {
  SphereSearch s;
  s.centre_hint_mm = {600, 300, 55};  // 200 mm from the sphere
  auto e = MeasureSphere(Scene({600, 100, 55}, 12.5, 0), s, 0.003, "bb-3.a");
  ASSERT_EQ(e.status().code(), absl::StatusCode::kNotFound);
  EXPECT_NE(e.status().message().find("bb-3.a"), std::string::npos);
  EXPECT_NE(e.status().message().find("not in the scan"), std::string::npos);
  // The hint on the floor: points, but no sphere of that size there.
  s.centre_hint_mm = {640, 140, 35};
  auto floor = MeasureSphere(Scene({600, 100, 55}, 12.5, 0), s, 0.003, "sphere-2");
  ASSERT_FALSE(floor.ok());
  EXPECT_NE(floor.status().message().find("sphere-2"), std::string::npos);
}

}  // namespace
}  // namespace surfinspect
