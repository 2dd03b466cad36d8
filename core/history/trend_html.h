// trend.html: one self-contained page (no scripts, no network) with, per
// characteristic, the SPC table (n, mean, sigma within/overall, Cp, Cpk, Pp,
// Ppk, slope and its confidence interval), the individuals chart and the
// moving-range chart as inline SVG with their control limits, the drift line
// and the Western Electric violations marked in red; then the trend map
// picture (trend.png, embedded) when there is one.
#pragma once

#include <string>

#include "core/history/trend.h"

namespace surfinspect {

// `map_png` is PNG bytes, or empty for no map.
std::string TrendHtml(const Trend& trend, const std::string& title, const std::string& map_png);

}  // namespace surfinspect
