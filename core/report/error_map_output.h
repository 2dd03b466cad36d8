// Files an inspector opens from an error map: a coloured binary PLY and a CSV with one row per
// input point, each written atomically. The PNG picture is in core/report/error_map_png.h, the
// JSON report in core/pipeline/inspection_report.h.
#pragma once

#include <string>

#include "absl/status/status.h"
#include "core/errormap/deviation_color.h"
#include "core/errormap/error_map.h"
#include "core/io/png_image.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

// Binary little-endian PLY of the finite points of `points` (whatever frame
// the caller chose; say it in `frame_name`, stored as a comment), each with
// float x y z, the deviation twice (float scalar_deviation and float
// quality: mm, NaN when unmatched) and uchar red green blue from
// DeviationColor. Fails if the sizes of points and result differ.
// What peers load (checked with Debian's CloudCompare 2.11.3 and vcglib's
// PLY importer): CloudCompare takes a vertex property as a scalar field only
// when its name contains "scal", so `scalar_deviation` is its scalar field
// "deviation" (NaN kept) and `quality` is dropped; MeshLab maps `quality` to
// the per-vertex quality and drops `scalar_deviation`; both show red green
// blue as the vertex colour.
absl::Status WriteErrorMapPly(const std::string& path, const PointCloud& points,
                              const ErrorMapResult& result, const std::string& frame_name);

// CSV with header x,y,z,deviation (plus dx,dy,dz,normal_deviation when the
// result has split components), one row per input point in input order,
// `nan` where a value is missing. Floats are printed round-trip exact.
absl::Status WriteErrorMapCsv(const std::string& path, const PointCloud& points,
                              const ErrorMapResult& result);

}  // namespace surfinspect
