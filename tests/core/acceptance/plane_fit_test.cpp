// core/acceptance/plane_fit.cpp against known planes: exact, noisy (tilt σ
// against 200 seeded fits), and degenerate input.
#include "core/acceptance/plane_fit.h"

#include <gtest/gtest.h>

#include <random>

namespace surfinspect {
namespace {

std::vector<Eigen::Vector3d> Patch(const Eigen::Vector3d& n, double noise, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-40, 40);
  std::normal_distribution<double> g(0, noise > 0 ? noise : 1);
  const Eigen::Vector3d a = n.unitOrthogonal(), b = n.cross(a);
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < 1000; ++i)
    pts.push_back(Eigen::Vector3d(5, 6, 7) + u(rng) * a + 0.5 * u(rng) * b +
                  (noise > 0 ? g(rng) : 0.0) * n);
  return pts;
}

TEST(PlaneFit, ExactPointsGiveThePlane) {
  const Eigen::Vector3d n = Eigen::Vector3d(0.1, -0.2, 1).normalized();
  auto f = FitPlane(Patch(n, 0, 3));
  ASSERT_TRUE(f.ok()) << f.status();
  EXPECT_LT((f->normal - n).norm(), 1e-12);
  EXPECT_NEAR(n.dot(f->point - Eigen::Vector3d(5, 6, 7)), 0, 1e-9);
  EXPECT_LT(f->rms, 1e-9);
}

TEST(PlaneFit, TiltVarianceMatchesTheSpreadOfSeededFits) {
  const Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
  double sum1 = 0, sum2 = 0, rep1 = 0, rep2 = 0;
  for (uint64_t seed = 1; seed <= 200; ++seed) {
    auto f = FitPlane(Patch(n, 0.015, seed));
    ASSERT_TRUE(f.ok());
    sum1 += std::pow(f->normal.dot(f->axis1), 2) / 200;  // 0 by construction; tilt below
    const Eigen::Vector3d tilt = f->normal - n;
    // The true normal's component along each fitted in-plane axis is the tilt.
    const double t1 = n.dot(f->axis1), t2 = n.dot(f->axis2);
    sum2 += (t1 * t1 + t2 * t2) / 200;
    rep1 += f->tilt_variance1 / 200;
    rep2 += f->tilt_variance2 / 200;
    EXPECT_LT(tilt.norm(), 0.01);
  }
  EXPECT_LT(sum1, 1e-20);
  EXPECT_NEAR(sum2 / (rep1 + rep2), 1.0, 0.2);
}

TEST(PlaneFit, TooFewOrCollinearPointsAreClearErrors) {
  auto few = FitPlane({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  EXPECT_EQ(few.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(few.status().message().find("at least 10"), std::string::npos);
  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 20; ++i) line.emplace_back(i, 2 * i, 0);
  EXPECT_EQ(FitPlane(line).status().code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace surfinspect
