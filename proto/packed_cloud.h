// A request's cloud without its "no data" points: xyz holds only the points
// with data, and valid_bits says where they go in the grid (the wire format
// is documented at v1.PointCloud.valid_bits). An organized 1024x768 view is
// a third NaN, so its requests shrink by about as much. Responses keep the
// whole grid, which every client decodes.
#pragma once

#include <cstdint>
#include <string>

#include "absl/status/statusor.h"
#include "core/types/point_cloud.h"
#include "surfinspect/v1/inspection.pb.h"

namespace surfinspect::wire {

// The bytes of a point left out of a packed cloud: three quiet NaNs, the
// spelling of "no data" of the readers and the simulator. Only points of
// exactly these bytes are left out, so unpacking restores every byte.
bool IsPackedAway(const Eigen::Vector3f& p);

// The cloud for a request: packed when that is smaller (some point is
// packed away), the whole grid otherwise.
void CloudToRequestProto(const PointCloud& cloud, v1::PointCloud* msg);

// Unpacks `xyz` by `valid_bits` into a width x height cloud and validates
// it. InvalidArgument, naming `field`, when valid_bits is not
// ceil(width*height/8) bytes, sets a bit past the last point, or does not
// count as many points as xyz holds; or when a point is infinite.
absl::StatusOr<PointCloud> CloudFromPackedBytes(const std::string& xyz,
                                                const std::string& valid_bits, uint32_t width,
                                                uint32_t height, const std::string& field);

}  // namespace surfinspect::wire
