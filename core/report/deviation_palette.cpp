#include "core/report/deviation_palette.h"

#include <cmath>
#include <limits>

#include "core/errormap/deviation_color.h"

namespace surfinspect {
namespace {

// Position 0..1 of |d| between the band's edge and the range, as
// DeviationColor computes it (1 when the range does not exceed the band).
double OuterFraction(double abs_d, double tol, double range) {
  return range > tol ? (abs_d - tol) / (range - tol) : 1.0;
}

int RunBin(double fraction) {
  const int bin = static_cast<int>(std::floor(fraction * kPaletteRun));
  return bin < 0 ? 0 : bin >= kPaletteRun ? kPaletteRun - 1 : bin;
}

}  // namespace

DeviationPalette MakeDeviationPalette(double tol, double range) {
  DeviationPalette p;
  p.tolerance_mm = tol;
  p.range_mm = range;
  p.colors.fill(kUnmatchedGrey);
  const double inf = std::numeric_limits<double>::infinity();
  p.colors[kPaletteBeyondBelow] = DeviationColor(-inf, tol, range);
  p.colors[kPaletteBeyondAbove] = DeviationColor(inf, tol, range);
  for (int k = 0; k < kPaletteRun; ++k) {
    const double centre = (k + 0.5) / kPaletteRun;  // of bin k, 0..1
    p.colors[kPaletteBand + k] = DeviationColor(tol * (2 * centre - 1), tol, range);
    // A deviation just outside the band when the range does not exceed it.
    const double outer = range > tol ? tol + centre * (range - tol) : std::nextafter(tol, inf);
    p.colors[kPaletteAbove + k] = DeviationColor(outer, tol, range);
    // Below runs from -range up to -tol, so bin 0 is the farthest.
    p.colors[kPaletteBelow + kPaletteRun - 1 - k] = DeviationColor(-outer, tol, range);
  }
  return p;
}

uint8_t PaletteIndex(const DeviationPalette& p, float deviation_mm) {
  const double d = deviation_mm;
  if (std::isnan(d)) return kPaletteUnmatched;
  const double tol = p.tolerance_mm;
  if (std::abs(d) <= tol) {
    const double fraction = tol > 0 ? (d / tol + 1) / 2 : 0.5;
    return static_cast<uint8_t>(kPaletteBand + RunBin(fraction));
  }
  const double s = OuterFraction(std::abs(d), tol, p.range_mm);
  if (s > 1) return d > 0 ? kPaletteBeyondAbove : kPaletteBeyondBelow;
  const int bin = RunBin(s);
  return static_cast<uint8_t>(d > 0 ? kPaletteAbove + bin : kPaletteBelow + kPaletteRun - 1 - bin);
}

}  // namespace surfinspect
