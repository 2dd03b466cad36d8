#include "core/errormap/deviation_color.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <utility>
#include <vector>

namespace surfinspect {
namespace {

TEST(DeviationColor, ColourScaleIsDivergingWithToleranceBands) {
  const double tol = 0.1, range = 0.5;
  EXPECT_EQ(DeviationColor(NAN, tol, range), kUnmatchedGrey);
  for (double d : {-0.1, -0.05, 0.0, 0.05, 0.1}) {
    const Rgb c = DeviationColor(d, tol, range);
    EXPECT_GT(c.g, c.r);
    EXPECT_GT(c.g, c.b);
  }
  for (double d : {0.11, 0.3, 0.5}) {  // warm: red dominates, no blue
    const Rgb c = DeviationColor(d, tol, range);
    EXPECT_GT(c.r, 200);
    EXPECT_EQ(c.b, 0);
  }
  for (double d : {-0.11, -0.3, -0.5}) {
    const Rgb c = DeviationColor(d, tol, range);
    EXPECT_GT(c.b, 180);
    EXPECT_EQ(c.r, 0);
  }
  EXPECT_GT(DeviationColor(0.12, tol, range).g, DeviationColor(0.45, tol, range).g)
      << "yellow to red";
  EXPECT_FALSE(DeviationColor(0.6, tol, range) == DeviationColor(0.5, tol, range))
      << "beyond the scale";
}

// The colour scale piece by piece, as its definition reads (the oracle for
// the branch-free DeviationColor).
Rgb ReferenceLerp(Rgb a, Rgb b, double t) {
  auto mix = [t](uint8_t x, uint8_t y) {
    return static_cast<uint8_t>(std::lround(x + (static_cast<double>(y) - x) * t));
  };
  return {mix(a.r, b.r), mix(a.g, b.g), mix(a.b, b.b)};
}
Rgb ReferenceColor(double d, double tol, double range) {
  if (std::isnan(d)) return kUnmatchedGrey;
  if (std::abs(d) <= tol) {
    const double t = tol > 0 ? d / tol : 0.0;
    return ReferenceLerp(Rgb{40, 190, 90}, t >= 0 ? Rgb{150, 215, 60} : Rgb{40, 190, 170},
                         std::abs(t));
  }
  const double s = range > tol ? (std::abs(d) - tol) / (range - tol) : 1.0;
  if (s > 1) return d > 0 ? Rgb{120, 0, 50} : Rgb{50, 0, 120};
  const Rgb at0 = d > 0 ? Rgb{255, 235, 0} : Rgb{0, 230, 230};
  const Rgb at_half = d > 0 ? Rgb{255, 140, 0} : Rgb{0, 120, 255};
  const Rgb at1 = d > 0 ? Rgb{215, 0, 0} : Rgb{0, 0, 190};
  return s < 0.5 ? ReferenceLerp(at0, at_half, 2 * s) : ReferenceLerp(at_half, at1, 2 * s - 1);
}

TEST(DeviationColor, ColourIsTheScalesPiecewiseDefinition) {
  std::mt19937_64 rng(19);
  int checked = 0;
  for (const auto& [tol, range] : std::vector<std::pair<double, double>>{
           {0.1, 0.5}, {0.05, 0.2}, {0.1, 0.1}, {0.3, 0.2}, {0.0, 1.0}, {-0.1, 0.5}, {1e-3, 25}}) {
    std::vector<double> ds = {0.0, -0.0, INFINITY, -INFINITY, NAN};
    const double half = tol + 0.5 * (range - tol);
    for (double edge : {tol, range, half, 0.5 * tol})
      for (double sign : {1.0, -1.0})
        for (double e : {sign * edge, std::nextafter(sign * edge, 0.0),
                         std::nextafter(sign * edge, sign * INFINITY)})
          ds.push_back(e);
    std::uniform_real_distribution<double> u(-2 * std::abs(range), 2 * std::abs(range));
    for (int i = 0; i < 20000; ++i) ds.push_back(static_cast<float>(u(rng)));
    for (double d : ds) {
      const Rgb got = DeviationColor(d, tol, range), want = ReferenceColor(d, tol, range);
      ASSERT_TRUE(got == want) << "d " << d << " tol " << tol << " range " << range;
      ++checked;
    }
  }
  EXPECT_GT(checked, 140000);
}

}  // namespace
}  // namespace surfinspect
