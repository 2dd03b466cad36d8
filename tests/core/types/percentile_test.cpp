// core/types/percentile.cpp against values worked out by hand (NumPy's
// default "linear" rule gives the same).
#include "core/types/percentile.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
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

// The counting form against the selection form, bit for bit: small and
// large counts, heavy ties, negative values and both zeros.
TEST(Percentile, FloatPercentilesEqualTheSelectionToTheBit) {
  std::mt19937 rng(9);
  std::normal_distribution<float> g(0.f, 0.3f);
  const std::vector<double> qs = {0.0, 0.01, 0.05, 0.5, 0.95, 0.99, 0.999};
  for (std::size_t n :
       {std::size_t{1}, std::size_t{2}, std::size_t{3}, std::size_t{1000}, std::size_t{200000}}) {
    for (int kind = 0; kind < 3; ++kind) {
      std::vector<float> v(n);
      for (float& x : v) {
        x = g(rng);
        if (kind == 1) x = std::round(x * 20) / 20;  // few distinct values
        if (kind == 2 && rng() % 3 == 0) x = rng() % 2 ? 0.f : -0.f;
      }
      const std::vector<double> got = FloatPercentiles(v, qs);
      std::vector<float> copy = v;
      Percentiles<float> want(copy);
      for (std::size_t i = 0; i < qs.size(); ++i) {
        const double w = want.At(qs[i]);
        ASSERT_EQ(std::memcmp(&got[i], &w, sizeof w), 0)
            << "n " << n << " kind " << kind << " q " << qs[i] << ": " << got[i] << " vs " << w;
      }
    }
  }
  EXPECT_TRUE(std::isnan(FloatPercentiles({}, {0.5})[0]));
  EXPECT_TRUE(std::isnan(FloatPercentiles({1.f, 2.f}, {1.0})[0]));
}

TEST(Percentile, MedianAndMadSigma) {
  std::vector<double> odd = {5, 1, 3}, even = {4, 1, 3, 2}, none;
  EXPECT_EQ(MedianInPlace(odd), 3);
  EXPECT_EQ(MedianInPlace(even), 2.5);
  EXPECT_TRUE(std::isnan(MedianInPlace(none)));
  std::vector<double> abs_residuals = {0.3, 0.1, 0.2, 0.4};  // median 0.25
  EXPECT_DOUBLE_EQ(MadSigma(abs_residuals), 1.4826 * 0.25);
  EXPECT_TRUE(std::isnan(MadSigma(none)));
}

}  // namespace
}  // namespace surfinspect
