// The error map's colour scale, shared by every picture of it (the PLY's
// vertex colours, the PNG, the PDF's maps, the HTML viewer's palette and the
// trend map): one function from a deviation to a colour.
#pragma once

#include "core/io/png_image.h"

namespace surfinspect {

// The diverging colour scale, centred on 0 (paper Fig. 11: red above the CAD
// surface, blue below): green inside +-tolerance (tinted warm/cool by sign),
// yellow -> red from +tol to +range, cyan -> blue from -tol to -range, darker
// still beyond the range, grey for NaN (unmatched).
Rgb DeviationColor(double deviation_mm, double tolerance_mm, double range_mm);
inline constexpr Rgb kUnmatchedGrey{150, 150, 150};

}  // namespace surfinspect
