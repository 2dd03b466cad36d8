// Covers core/types/round_half_away.h against std::lround: integers,
// halves, the doubles either side of each half, and random values.
#include "core/types/round_half_away.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace surfinspect {
namespace {

TEST(RoundHalfAwayFromZero, EqualsLroundAtHalvesAndTheirNeighbours) {
  std::vector<double> values = {0.0, -0.0, 1e-300, -1e-300, 0x1p51, -0x1p51, 0x1p52 - 0.5};
  for (int k = -300; k <= 300; ++k) {
    const double half = k + 0.5;
    for (double v :
         {double(k), half, std::nextafter(half, -INFINITY), std::nextafter(half, INFINITY),
          std::nextafter(double(k), -INFINITY), std::nextafter(double(k), INFINITY)})
      values.push_back(v);
  }
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-1e6, 1e6), small(-3, 3);
  for (int i = 0; i < 100000; ++i) values.push_back(i % 2 ? u(rng) : small(rng));
  for (double v : values) EXPECT_EQ(RoundHalfAwayFromZero(v), std::lround(v)) << v;
}

}  // namespace
}  // namespace surfinspect
