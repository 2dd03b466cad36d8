// Point-cloud files through PCL's readers and writers (the only translation
// unit that includes PCL's I/O headers, to keep builds fast).
//
// Supported: PCD (ascii, binary, binary_compressed; organized grids and NaN
// pixels kept bit-exact) and PLY (ascii, binary little/big endian). The x, y,
// z fields may be float32 or float64; other fields are ignored. Every file
// header is checked against the file size before PCL parses it, because
// PCL's parsers trust declared counts (see FIELD-NOTES: OSS-Fuzz reports).
#pragma once

#include <cstdint>
#include <string>

#include "absl/status/statusor.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

enum class PcdEncoding { kAscii, kBinary, kBinaryCompressed };

struct CloudReadLimits {
  uint64_t max_points = 200'000'000;  // refuse larger declared counts
};

// Dispatches on the extension (.pcd or .ply, case-insensitive).
absl::StatusOr<PointCloud> ReadPointCloud(const std::string& path,
                                          const CloudReadLimits& limits = {});

// PCD keeps the grid; PLY stores only the valid points (PLY has no grid).
// Written atomically (temporary file, then rename).
absl::Status WritePointCloud(const std::string& path, const PointCloud& cloud,
                             PcdEncoding pcd_encoding = PcdEncoding::kBinary,
                             bool ply_binary = true);

}  // namespace surfinspect
