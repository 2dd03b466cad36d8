// core/types/percentile.cpp against values worked out by hand (NumPy's
// default "linear" rule gives the same).
#include "core/types/percentile.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace surfinspect {
namespace {

TEST(Percentile, LinearInterpolationBetweenOrderStatistics) {
  // Sorted: 1 2 3 4 10; pos = q * 4.
  std::vector<double> v = {10, 3, 1, 4, 2};
  Percentiles<double> p(v);
  EXPECT_DOUBLE_EQ(p.At(0.0), 1.0);
  EXPECT_DOUBLE_EQ(p.At(0.10), 1.4);  // pos 0.4: 1 + 0.4 * (2 - 1)
  EXPECT_DOUBLE_EQ(p.At(0.50), 3.0);  // pos 2
  EXPECT_DOUBLE_EQ(p.At(0.90), 7.6);  // pos 3.6: 4 + 0.6 * (10 - 4)
  EXPECT_DOUBLE_EQ(p.At(1.0), 10.0);
}

TEST(Percentile, EvenCountMedianIsTheMidpoint) {
  std::vector<float> v = {4, 1, 3, 2};
  Percentiles<float> p(v);
  EXPECT_DOUBLE_EQ(p.At(0.5), 2.5);    // pos 1.5
  EXPECT_DOUBLE_EQ(p.At(0.95), 3.85);  // pos 2.85: 3 + 0.85
}

TEST(Percentile, OneValueAndNone) {
  std::vector<double> one = {7};
  Percentiles<double> p(one);
  EXPECT_EQ(p.At(0.01), 7.0);
  EXPECT_EQ(p.At(0.99), 7.0);
  std::vector<double> none;
  EXPECT_TRUE(std::isnan(Percentiles<double>(none).At(0.5)));
}

TEST(Percentile, IncreasingQueriesMatchAFullSort) {
  std::mt19937 rng(5);
  std::normal_distribution<double> g;
  std::vector<double> v(1001);
  for (double& x : v) x = g(rng);
  std::vector<double> sorted = v;
  std::sort(sorted.begin(), sorted.end());
  Percentiles<double> p(v);
  for (double q : {0.01, 0.05, 0.5, 0.95, 0.99}) {
    const double pos = q * 1000;
    const auto lo = static_cast<std::size_t>(pos);
    const double want = sorted[lo] + (pos - lo) * (sorted[lo + 1] - sorted[lo]);
    EXPECT_DOUBLE_EQ(p.At(q), want) << q;
  }
}

}  // namespace
}  // namespace surfinspect
