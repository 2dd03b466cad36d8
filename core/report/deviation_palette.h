// The error map's colour scale (core/errormap/deviation_color.h
// DeviationColor) as a 256-entry palette, so a page can colour points by a
// one-byte index: the HTML report ships the palette and one index per point.
//
// Layout: 0 unmatched (NaN), 1 beyond -range, 2..85 below the band
// [-range, -tol), 86..169 the band [-tol, +tol], 170..253 above the band
// (+tol, +range], 254 beyond +range. Each run of 84 samples DeviationColor at
// its bins' centres. Band membership is decided on the float deviation with
// DeviationColor's own comparisons, so a point is inside the band on the
// page exactly when it is inside on the PNG; within a run the colour is
// DeviationColor's at a deviation at most half a bin (range/168 mm) away.
#pragma once

#include <array>
#include <cstdint>

#include "core/io/png_image.h"

namespace surfinspect {

inline constexpr int kPaletteRun = 84;
inline constexpr uint8_t kPaletteUnmatched = 0, kPaletteBeyondBelow = 1, kPaletteBelow = 2,
                         kPaletteBand = 86, kPaletteAbove = 170, kPaletteBeyondAbove = 254;

struct DeviationPalette {
  double tolerance_mm = 0, range_mm = 0;
  std::array<Rgb, 256> colors{};  // entry 255 unused (grey)
};

// tolerance_mm > 0; range_mm <= tolerance_mm makes every run outside the
// band DeviationColor's end colour, as DeviationColor does.
DeviationPalette MakeDeviationPalette(double tolerance_mm, double range_mm);

// The palette index of a deviation (mm; NaN = unmatched).
uint8_t PaletteIndex(const DeviationPalette& palette, float deviation_mm);

}  // namespace surfinspect
