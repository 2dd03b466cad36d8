// A point cloud from PLY bytes (ply_format.h does the parsing): the vertex
// element's x, y and z (float32 or float64; other properties and elements
// are read past). PLY stores no grid, so the cloud comes out unorganized,
// in vertex order, as PCL's reader gave it. obj_info num_cols / num_rows
// must multiply to the vertex count; with a range_grid element of that many
// cells (PCL's organized PLY), empty cells become NaN points.
#pragma once

#include <string_view>

#include "absl/status/statusor.h"
#include "core/io/read_limits.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

absl::StatusOr<PointCloud> ParsePlyCloud(std::string_view bytes, const CloudReadLimits& limits = {},
                                         std::string_view name = "<ply>");

}  // namespace surfinspect
