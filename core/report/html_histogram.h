// The report's deviation histogram as an inline SVG for the HTML report:
// one bar per bin on a log10(1 + count) axis, so a bin holding nearly every
// point leaves the others readable, each coloured with the error map's
// palette at the bin's centre; the +-tolerance band shaded behind the bars,
// mm labels at -range, -tol, 0, +tol and +range.
#pragma once

#include <string>

#include "core/errormap/error_map.h"
#include "core/report/deviation_palette.h"

namespace surfinspect {

// The report's histogram; an empty one gives a short note.
std::string HistogramSvg(const Histogram& histogram, const DeviationPalette& palette);

}  // namespace surfinspect
