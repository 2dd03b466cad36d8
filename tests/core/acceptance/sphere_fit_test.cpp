// core/acceptance/sphere_fit.cpp against known spheres: exact points, noisy
// points (the reported covariance against the spread of 200 seeded fits),
// a cap of a sphere, and inputs that do not fix a sphere.
#include "core/acceptance/sphere_fit.h"

#include <gtest/gtest.h>

#include <random>

namespace surfinspect {
namespace {

std::vector<Eigen::Vector3d> Cap(const Eigen::Vector3d& c, double r, double max_polar_deg,
                                 std::size_t n, double noise, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> g(0, noise > 0 ? noise : 1);
  const double cmin = std::cos(max_polar_deg * M_PI / 180);
  std::vector<Eigen::Vector3d> pts;
  for (std::size_t i = 0; i < n; ++i) {
    const double z = cmin + (1 - cmin) * u(rng), phi = 2 * M_PI * u(rng);
    const double s = std::sqrt(1 - z * z);
    const Eigen::Vector3d dir(s * std::cos(phi), s * std::sin(phi), z);
    pts.push_back(c + (r + (noise > 0 ? g(rng) : 0.0)) * dir);
  }
  return pts;
}

TEST(SphereFit, ExactPointsGiveTheSphere) {
  const Eigen::Vector3d c(612.3, 101.7, 55.2);
  auto f = FitSphere(Cap(c, 12.5, 70, 500, 0, 1));
  ASSERT_TRUE(f.ok()) << f.status();
  EXPECT_LT((f->centre - c).norm(), 1e-9);
  EXPECT_NEAR(f->radius, 12.5, 1e-9);
  EXPECT_LT(f->rms, 1e-9);
  EXPECT_TRUE(f->converged);
}

TEST(SphereFit, CovarianceMatchesTheSpreadOfSeededFits) {
  const Eigen::Vector3d c(0, 0, 0);
  std::vector<double> dz, dr;
  double reported_z = 0, reported_r = 0;
  for (uint64_t seed = 1; seed <= 200; ++seed) {
    auto f = FitSphere(Cap(c, 12.5, 60, 800, 0.015, seed));
    ASSERT_TRUE(f.ok());
    dz.push_back(f->centre.z());
    dr.push_back(f->radius - 12.5);
    reported_z += std::sqrt(f->covariance(2, 2)) / 200;
    reported_r += std::sqrt(f->covariance(3, 3)) / 200;
  }
  const auto sd = [](const std::vector<double>& v) {
    double m = 0, s = 0;
    for (double x : v) m += x / v.size();
    for (double x : v) s += (x - m) * (x - m) / (v.size() - 1);
    return std::sqrt(s);
  };
  // A cap leaves the centre's z and the radius correlated and far less
  // certain than the noise / sqrt(n); the reported σ must follow (±20 %).
  EXPECT_NEAR(sd(dz) / reported_z, 1.0, 0.2);
  EXPECT_NEAR(sd(dr) / reported_r, 1.0, 0.2);
  EXPECT_GT(reported_r, 3 * 0.015 / std::sqrt(800.0));
}

TEST(SphereFit, TooFewOrPlanarPointsAreClearErrors) {
  auto few = FitSphere(Cap({0, 0, 0}, 10, 60, 9, 0, 1));
  EXPECT_EQ(few.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(few.status().message().find("at least 10"), std::string::npos);
  std::vector<Eigen::Vector3d> plane;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) plane.emplace_back(i, j, 0);
  auto flat = FitSphere(plane);
  EXPECT_EQ(flat.status().code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace surfinspect
