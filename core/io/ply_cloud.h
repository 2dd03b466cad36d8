// A point cloud from PLY bytes (ply_format.h does the parsing): the vertex
// element's x, y and z (float32 or float64; other properties and elements
// are read past). obj_info num_cols / num_rows must multiply to the vertex
// count or, with a range_grid element of another size (the Stanford range
// scans', PCL's organized PLY), to its cell count: cell r holds its first
// vertex, an empty cell a NaN point. With both, the cloud is organized,
// width num_cols, height num_rows, cell r at row r / num_cols, column
// r % num_cols (as PCL's reader gives it); without, it is unorganized.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "absl/status/statusor.h"
#include "core/io/read_limits.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

absl::StatusOr<PointCloud> ParsePlyCloud(std::string_view bytes, const CloudReadLimits& limits = {},
                                         std::string_view name = "<ply>");

// The file at `path` read as ParsePlyCloud would read its bytes, with the
// same cloud or error, for the one layout whose data section is the
// points' own: binary little-endian, a single `vertex` element of float32
// x, y, z and nothing else. Its header is parsed from the file's first
// bytes and its rows are read from the file straight into the cloud,
// without a copy of the whole file (for 10^6 points, 12 MB fewer to fault
// in and copy). nullopt, having returned nothing, for any other file or
// one that cannot be read so: the caller then reads the file whole.
std::optional<absl::StatusOr<PointCloud>> ReadPackedXyzPly(const std::string& path,
                                                           const CloudReadLimits& limits = {});

}  // namespace surfinspect
