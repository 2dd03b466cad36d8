// trend.html: one self-contained page (no scripts, no network) with, per
// characteristic, the SPC table (n, mean, sigma within/overall, Cp, Cpk, Pp,
// Ppk, slope and its confidence interval), the individuals chart and the
// moving-range chart as inline SVG with their control limits, the drift line
// and the Western Electric violations marked in red; then the trend map
// picture (trend.png, embedded) when there is one. TrendViewerHtml shows
// the map in 3D instead.
#pragma once

#include <string>

#include "absl/status/statusor.h"
#include "core/history/trend.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

// `map_png` is PNG bytes, or empty for no map.
std::string TrendHtml(const Trend& trend, const std::string& title, const std::string& map_png);

// With the CAD mesh the map belongs to: the same sections beside the 3D
// viewer of report.html (core/report/viewer_page.h, data.kind "trend_map"),
// which draws every triangle in the error map's colours for its mean over
// the parts (range the largest |mean|, band a quarter of it, as trend.png)
// or, switched, for its sigma over the parts (range the largest sigma);
// the pointer shows a triangle's mean, sigma and part count. Self-contained
// (three.js is inline), so it opens from file:// with no network.
// InvalidArgument when the map has a triangle id the mesh does not.
absl::StatusOr<std::string> TrendViewerHtml(const Trend& trend, const std::string& title,
                                            const TriangleMesh& mesh);

}  // namespace surfinspect
