// The data section of a PCD file, after pcd_format.h parsed its header:
// ascii lines, binary point records, or a binary_compressed LZF block that
// holds the fields one after another (all x values, then all y values, ...).
// x, y and z come out as float (float64 values converted), bit-identical to
// PCL's reader; other fields are read past. Sizes are checked against the
// buffer before anything is allocated.
#pragma once

#include <string_view>

#include "absl/status/statusor.h"
#include "core/io/pcd_format.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

// `bytes` is the whole file; h.data_offset says where the data starts. The
// cloud keeps the header's grid; it is not yet validated.
absl::StatusOr<PointCloud> DecodePcdData(std::string_view bytes, const PcdHeader& h,
                                         std::string_view name);

}  // namespace surfinspect
