// SPC against the textbook: a series worked by hand, and random series
// against the formulas written out here independently (long double, direct
// sums), with d2 = 1.128 and D4 = 3.267 for moving ranges of 2.
#include "core/history/spc.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace surfinspect {
namespace {

TEST(Spc, HandWorkedSeries) {
  // x = 10 12 11 13 12, LSL 5, USL 17. MR = 2 1 2 1, MRbar = 1.5,
  // sigma_w = 1.5 / 1.128 = 1.329787; mean 11.6; s = sqrt(5.2 / 4) = 1.140175.
  auto r = ComputeSpc({10, 12, 11, 13, 12}, 5, 17);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(r->n, 5u);
  EXPECT_NEAR(r->mean_mm, 11.6, 1e-12);
  EXPECT_NEAR(r->mr_bar_mm, 1.5, 1e-12);
  EXPECT_NEAR(r->sigma_within_mm, 1.329787, 1e-6);
  EXPECT_NEAR(r->sigma_overall_mm, 1.140175, 1e-6);
  EXPECT_NEAR(r->cp, 12 / (6 * 1.329787), 1e-5);    // 1.50400
  EXPECT_NEAR(r->cpk, 5.4 / (3 * 1.329787), 1e-5);  // 1.35360
  EXPECT_NEAR(r->pp, 12 / (6 * 1.140175), 1e-5);    // 1.75412
  EXPECT_NEAR(r->ppk, 5.4 / (3 * 1.140175), 1e-5);  // 1.57871
  EXPECT_NEAR(r->individuals.upper, 11.6 + 3 * 1.329787, 1e-5);
  EXPECT_NEAR(r->individuals.lower, 11.6 - 3 * 1.329787, 1e-5);
  EXPECT_NEAR(r->moving_range.upper, 3.267 * 1.5, 1e-12);
  EXPECT_EQ(r->moving_range.lower, 0);
}

TEST(Spc, RandomSeriesEqualTheTextbookFormulas) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.02);
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 2 + trial % 60;
    std::vector<double> x;
    for (int i = 0; i < n; ++i) x.push_back(0.01 + noise(rng));
    const double lsl = -0.1, usl = 0.15;
    long double sum = 0, mr = 0;
    for (int i = 0; i < n; ++i) sum += x[i];
    for (int i = 1; i < n; ++i) mr += std::fabs(static_cast<long double>(x[i]) - x[i - 1]);
    const long double mean = sum / n, mr_bar = mr / (n - 1), sw = mr_bar / 1.128L;
    long double ss = 0;
    for (int i = 0; i < n; ++i) ss += (x[i] - mean) * (x[i] - mean);
    const long double so = std::sqrt(ss / (n - 1));
    auto r = ComputeSpc(x, lsl, usl);
    ASSERT_TRUE(r.ok());
    const double tol = 1e-9;
    EXPECT_NEAR(r->mean_mm, mean, tol);
    EXPECT_NEAR(r->sigma_within_mm, sw, tol);
    EXPECT_NEAR(r->sigma_overall_mm, so, tol);
    EXPECT_NEAR(r->cp, (usl - lsl) / (6 * sw), 1e-7);
    EXPECT_NEAR(r->cpk, std::min(usl - mean, mean - lsl) / (3 * sw), 1e-7);
    EXPECT_NEAR(r->pp, (usl - lsl) / (6 * so), 1e-7);
    EXPECT_NEAR(r->ppk, std::min(usl - mean, mean - lsl) / (3 * so), 1e-7);
    EXPECT_NEAR(r->individuals.upper, mean + 3 * sw, tol);
    EXPECT_NEAR(r->moving_range.upper, 3.267L * mr_bar, tol);
  }
}

// A true position has an upper limit alone: no Cp or Pp, and Cpk, Ppk of
// the upper side (the hand-worked series above against USL 17).
TEST(Spc, OneSidedToleranceHasTheUpperSideOnly) {
  auto r = ComputeSpc({10, 12, 11, 13, 12}, -INFINITY, 17);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_TRUE(std::isnan(r->cp));
  EXPECT_TRUE(std::isnan(r->pp));
  EXPECT_NEAR(r->cpk, 5.4 / (3 * 1.329787), 1e-5);
  EXPECT_NEAR(r->ppk, 5.4 / (3 * 1.140175), 1e-5);
  EXPECT_NEAR(r->individuals.upper, 11.6 + 3 * 1.329787, 1e-5);
}

TEST(Spc, ConstantSeriesHasUndefinedIndices) {
  auto r = ComputeSpc({0.02, 0.02, 0.02}, -0.1, 0.1);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(std::isnan(r->cp));
  EXPECT_TRUE(std::isnan(r->ppk));
}

TEST(Spc, RefusesTooFewValuesAndEmptyTolerance) {
  EXPECT_FALSE(ComputeSpc({1.0}, 0, 2).ok());
  EXPECT_FALSE(ComputeSpc({1.0, 2.0}, 1, 1).ok());
  EXPECT_FALSE(ComputeSpc({1.0, NAN}, 0, 2).ok());
}

}  // namespace
}  // namespace surfinspect
