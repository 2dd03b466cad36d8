// The report's deviation histogram as an inline SVG for the HTML report:
// one bar per bin on a log10(1 + count) axis, so a bin holding nearly every
// point leaves the others readable, each coloured with the error map's
// palette at the bin's centre; the +-tolerance band shaded behind the bars,
// mm labels at -range, -tol, 0, +tol and +range.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "core/report/deviation_palette.h"

namespace surfinspect {

// `report` is report.json's object ("histogram": {min_mm, max_mm, counts,
// below_range, above_range}); an empty histogram gives a short note.
std::string HistogramSvg(const nlohmann::json& report, const DeviationPalette& palette);

}  // namespace surfinspect
