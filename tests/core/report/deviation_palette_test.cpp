#include "core/report/deviation_palette.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/errormap/deviation_color.h"

namespace surfinspect {
namespace {

int MaxChannelDifference(Rgb a, Rgb b) {
  return std::max({std::abs(a.r - b.r), std::abs(a.g - b.g), std::abs(a.b - b.b)});
}

TEST(DeviationPalette, MatchesTheErrorMapColourWithinHalfABin) {
  const double tol = 0.3, range = 1.0;
  const DeviationPalette p = MakeDeviationPalette(tol, range);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> d(-1.3, 1.3);
  for (int i = 0; i < 20000; ++i) {
    const float v = static_cast<float>(d(rng));
    const Rgb want = DeviationColor(v, tol, range);
    const Rgb got = p.colors[PaletteIndex(p, v)];
    // The steepest ramp (255 -> 0 over half the outer run) moves ~6 units per bin.
    EXPECT_LE(MaxChannelDifference(want, got), 4) << "deviation " << v;
  }
}

TEST(DeviationPalette, BandMembershipIsExact) {
  const DeviationPalette p = MakeDeviationPalette(0.3, 1.0);
  const float tol = 0.3f;
  // DeviationColor compares the float's double value with the tolerance.
  const float inside = std::nextafter(tol, 0.0f) <= 0.3 ? std::nextafter(tol, 0.0f) : tol;
  EXPECT_GE(PaletteIndex(p, inside), kPaletteBand);
  EXPECT_LT(PaletteIndex(p, inside), kPaletteAbove);
  const float outside = std::nextafter(std::nextafter(tol, 1.0f), 1.0f);
  EXPECT_EQ(PaletteIndex(p, outside), kPaletteAbove);
  EXPECT_EQ(PaletteIndex(p, -outside), kPaletteBand - 1);  // the last below bin, nearest -tol
  EXPECT_EQ(PaletteIndex(p, 0.0f), kPaletteBand + kPaletteRun / 2);
}

TEST(DeviationPalette, SpecialEntries) {
  const DeviationPalette p = MakeDeviationPalette(0.1, 0.5);
  EXPECT_EQ(PaletteIndex(p, NAN), kPaletteUnmatched);
  EXPECT_EQ(p.colors[kPaletteUnmatched].r, kUnmatchedGrey.r);
  EXPECT_EQ(PaletteIndex(p, 0.51f), kPaletteBeyondAbove);
  EXPECT_EQ(PaletteIndex(p, -0.51f), kPaletteBeyondBelow);
  EXPECT_EQ(PaletteIndex(p, 0.5f), kPaletteAbove + kPaletteRun - 1);
  EXPECT_EQ(PaletteIndex(p, -0.5f), kPaletteBelow);
  const Rgb beyond = DeviationColor(2.0, 0.1, 0.5);
  EXPECT_EQ(p.colors[kPaletteBeyondAbove].r, beyond.r);
  EXPECT_EQ(p.colors[kPaletteBeyondAbove].b, beyond.b);
}

TEST(DeviationPalette, RangeInsideTheBandGivesTheEndColour) {
  const DeviationPalette p = MakeDeviationPalette(0.3, 0.2);
  const Rgb want = DeviationColor(0.5, 0.3, 0.2);
  const Rgb got = p.colors[PaletteIndex(p, 0.5f)];
  EXPECT_EQ(MaxChannelDifference(want, got), 0);
}

}  // namespace
}  // namespace surfinspect
