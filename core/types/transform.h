// Rigid transforms in millimetres. A transform is named `to_from`, e.g.
// `world_from_sensor` maps sensor-frame coordinates into the world frame, so
// compositions read left to right: world_from_gauge * gauge_from_sensor.
#pragma once

#include <Eigen/Geometry>
#include <array>

#include "absl/status/statusor.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

// Row-major 4x4 as 16 doubles, the wire and file layout.
using RowMajor16 = std::array<double, 16>;

RowMajor16 ToRowMajor(const Eigen::Isometry3d& t);

// Accepts a 4x4 whose upper-left 3x3 is a rotation to within 1e-6 (R^T R = I,
// det = +1), whose last row is 0 0 0 1 and whose entries are finite. A
// rotation off by more than 1e-12 (e.g. printed with few digits) is
// re-orthonormalised; otherwise the matrix is kept bit for bit. `what` names the transform in the
// error message.
absl::StatusOr<Eigen::Isometry3d> FromRowMajor(const RowMajor16& row_major, absl::string_view what);

// Applies `to_from` to every valid point; NaN pixels stay NaN, so an
// organized grid stays organized. Computed in double, stored as float.
PointCloud TransformCloud(const PointCloud& cloud, const Eigen::Isometry3d& to_from);

// True when TransformCloud(cloud, to_from) would equal `cloud` bit for bit,
// so a caller may use `cloud` itself and skip the copy: `to_from` is the
// identity and no point has a -0 coordinate (the arithmetic, with its
// +0 translation, writes +0 there).
bool TransformKeepsCloud(const PointCloud& cloud, const Eigen::Isometry3d& to_from);

// Rotation angle (degrees) and translation length (mm) of a - b's difference
// a^-1 * b: the standard pose-error measure used in tests and reports.
struct PoseDifference {
  double translation_mm = 0;
  double rotation_deg = 0;
};
PoseDifference ComparePoses(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b);

}  // namespace surfinspect
