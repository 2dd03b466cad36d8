// trend.png: the process trend map drawn on the CAD part, seen along the
// mesh's thinnest axis (as the error-map PNG does), each triangle filled
// with the error map's colour scale (DeviationColor) for its mean deviation
// over the parts, with a colour bar. Triangles no part has points on are grey.
#pragma once

#include "absl/status/statusor.h"
#include "core/history/trend_map.h"
#include "core/io/png_image.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

struct TrendPngOptions {
  uint32_t map_width = 800;  // pixels of the map panel's longer side
  double range_mm = 0;       // colour scale +-range; 0 = the largest |mean|
  double band_mm = 0;        // green inside +-band; 0 = range / 4
};

// Fails when the map has a triangle id the mesh does not.
absl::StatusOr<RgbImage> RenderTrendMap(const TrendMap& map, const TriangleMesh& mesh_in_part,
                                        const TrendPngOptions& options = {});

}  // namespace surfinspect
