// Circle and slot fits against points on known contours, with noise and
// outliers (the robust rejection).
#include "core/plan/profile_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace surfinspect {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

std::vector<Vector2d> OnContour(const ProfileFit& shape, int n, double noise, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0, noise);
  std::vector<Vector2d> pts;
  const Vector2d perp(-shape.direction.y(), shape.direction.x());
  for (int k = 0; k < n; ++k) {
    const double a = 2 * M_PI * (k + 0.5) / n, r = shape.radius + g(rng);
    const double u = r * std::cos(a) + (std::cos(a) >= 0 ? 1 : -1) * shape.half_length;
    pts.push_back(shape.centre + u * shape.direction + r * std::sin(a) * perp);
  }
  return pts;
}

TEST(ProfileFit, ACircleThroughNoisyPointsAndOutliersIsTheTrueCircle) {
  ProfileFit truth;
  truth.centre = {3.2, -1.7};
  truth.radius = 4.0;
  std::vector<Vector2d> pts = OnContour(truth, 200, 0.01, 1);
  for (int k = 0; k < 10; ++k) pts[k * 20] *= 1.2;  // 5% outliers, 0.8 mm off and more
  auto fit = FitCircle2d(pts);
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_NEAR(fit->centre.x(), 3.2, 0.004);
  EXPECT_NEAR(fit->centre.y(), -1.7, 0.004);
  EXPECT_NEAR(fit->radius, 4.0, 0.004);
  EXPECT_EQ(fit->inliers, 190u) << "the outliers are rejected, nothing else";
  EXPECT_NEAR(fit->rms, 0.01, 0.003);
  EXPECT_EQ(FitCircle2d({{0, 0}, {1, 1}, {2, 2}, {3, 3}, {4, 4}, {5, 5}}).status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST(ProfileFit, ASlotIsFittedFromAShiftedTurnedStart) {
  ProfileFit truth;
  truth.slot = true;
  truth.centre = {1.0, 0.5};
  truth.direction = Vector2d(std::cos(0.3), std::sin(0.3));
  truth.radius = 3.0;
  truth.half_length = 4.0;
  const std::vector<Vector2d> pts = OnContour(truth, 300, 0.005, 2);
  ProfileFit start;
  start.radius = 3.3;
  start.half_length = 3.5;  // centre 0, direction x: 1.1 mm and 17 deg off
  auto fit = FitSlot2d(pts, start);
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_NEAR((fit->centre - truth.centre).norm(), 0, 0.003);
  EXPECT_NEAR(std::abs(fit->direction.dot(truth.direction)), 1, 1e-5);
  EXPECT_NEAR(fit->diameter(), 6.0, 0.003);
  EXPECT_NEAR(fit->length(), 14.0, 0.006);
  for (const Vector2d& p : pts) EXPECT_NEAR(ProfileDistance(truth, p), 0, 0.03);
}

}  // namespace
}  // namespace surfinspect
