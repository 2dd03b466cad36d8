// Point-cloud files: read by our own parsers (pcd_format.h, ply_cloud.h),
// written by our own encoders in PCL's layouts (cloud_write.h).
//
// Supported: PCD (ascii, binary, binary_compressed; organized grids and NaN
// pixels kept bit-exact) and PLY (ascii, binary little/big endian). The x, y,
// z fields may be float32 or float64; other fields are ignored. PCL's
// readers are not used: they trust declared counts and crash or abort on
// malformed headers, while ours refuse them with a message.
#pragma once

#include <string>

#include "absl/status/statusor.h"
#include "core/io/cloud_write.h"
#include "core/io/read_limits.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

// Dispatches on the extension (.pcd or .ply, case-insensitive).
absl::StatusOr<PointCloud> ReadPointCloud(const std::string& path,
                                          const CloudReadLimits& limits = {});

// PCD keeps the grid; PLY stores only the valid points (PLY has no grid).
// The header names the coordinates' unit (millimetres unless a command
// writes its input's unit back, as filter --out-units does).
// Written atomically (temporary file, then rename).
absl::Status WritePointCloud(const std::string& path, const PointCloud& cloud,
                             PcdEncoding pcd_encoding = PcdEncoding::kBinary,
                             bool ply_binary = true, std::string_view unit = "mm");

}  // namespace surfinspect
