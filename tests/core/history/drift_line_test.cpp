// The drift line: Student's t quantiles against printed tables, the slope
// and its standard error against the normal equations solved here, and the
// interval's coverage on simulated drifts.
#include "core/history/drift_line.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

namespace surfinspect {
namespace {

TEST(DriftLine, StudentTQuantilesMatchTables) {
  // Montgomery & Runger, Table V (two-sided 95% and 99% columns).
  EXPECT_NEAR(StudentTQuantile(0.975, 1), 12.706, 1e-3);
  EXPECT_NEAR(StudentTQuantile(0.975, 10), 2.228, 1e-3);
  EXPECT_NEAR(StudentTQuantile(0.975, 28), 2.048, 1e-3);
  EXPECT_NEAR(StudentTQuantile(0.995, 5), 4.032, 1e-3);
  EXPECT_NEAR(StudentTQuantile(0.95, 120), 1.658, 1e-3);
  EXPECT_NEAR(StudentTQuantile(0.025, 28), -2.048, 1e-3);
  EXPECT_NEAR(StudentTQuantile(0.5, 7), 0.0, 1e-9);
}

TEST(DriftLine, ExactLine) {
  std::vector<double> y;
  for (int i = 0; i < 10; ++i) y.push_back(2 + 0.5 * i);
  auto line = FitDriftLine(y);
  ASSERT_TRUE(line.ok());
  EXPECT_NEAR(line->slope_mm_per_part, 0.5, 1e-12);
  EXPECT_NEAR(line->intercept_mm, 2, 1e-12);
  EXPECT_NEAR(line->ci_lower, 0.5, 1e-9);
  EXPECT_NEAR(line->ci_upper, 0.5, 1e-9);
}

TEST(DriftLine, EqualsNormalEquations) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0, 0.015);
  for (int n : {3, 5, 30, 200}) {
    std::vector<double> y;
    Eigen::MatrixXd X(n, 2);
    Eigen::VectorXd Y(n);
    for (int i = 0; i < n; ++i) {
      y.push_back(0.01 + 0.005 * i + noise(rng));
      X(i, 0) = 1;
      X(i, 1) = i;
      Y(i) = y.back();
    }
    const Eigen::Matrix2d XtX_inv = (X.transpose() * X).inverse();
    const Eigen::Vector2d beta = XtX_inv * X.transpose() * Y;
    const double s2 = (Y - X * beta).squaredNorm() / (n - 2);
    const double se = std::sqrt(s2 * XtX_inv(1, 1));
    auto line = FitDriftLine(y);
    ASSERT_TRUE(line.ok());
    EXPECT_NEAR(line->slope_mm_per_part, beta(1), 1e-10);
    EXPECT_NEAR(line->intercept_mm, beta(0), 1e-10);
    EXPECT_NEAR(line->slope_se_mm_per_part, se, 1e-10);
    const double t = StudentTQuantile(0.975, n - 2);
    EXPECT_NEAR(line->ci_upper - line->ci_lower, 2 * t * se, 1e-10);
  }
}

TEST(DriftLine, IntervalCoversTheTrueSlope95PercentOfTheTime) {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> noise(0, 0.015);
  int covered = 0;
  const int trials = 4000;
  for (int t = 0; t < trials; ++t) {
    std::vector<double> y;
    for (int i = 0; i < 30; ++i) y.push_back(0.005 * i + noise(rng));
    auto line = FitDriftLine(y);
    ASSERT_TRUE(line.ok());
    covered += line->ci_lower <= 0.005 && 0.005 <= line->ci_upper;
  }
  EXPECT_NEAR(static_cast<double>(covered) / trials, 0.95, 0.015);
}

TEST(DriftLine, RefusesTooFewParts) {
  EXPECT_FALSE(FitDriftLine({1, 2}).ok());
  EXPECT_FALSE(FitDriftLine({1, 2, 3}, 1.0).ok());
}

}  // namespace
}  // namespace surfinspect
