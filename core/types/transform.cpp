#include "core/types/transform.h"

#include <cmath>
#include <cstdint>
#include <cstring>

#include "absl/strings/str_cat.h"
#include "core/types/float_scan.h"

namespace surfinspect {

RowMajor16 ToRowMajor(const Eigen::Isometry3d& t) {
  RowMajor16 out{};
  const Eigen::Matrix4d m = t.matrix();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out[r * 4 + c] = m(r, c);
  return out;
}

absl::StatusOr<Eigen::Isometry3d> FromRowMajor(const RowMajor16& row_major,
                                               absl::string_view what) {
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) {
      const double x = row_major[r * 4 + c];
      if (!std::isfinite(x))
        return absl::InvalidArgumentError(
            absl::StrCat(what, ": element (", r, ",", c, ") is not finite"));
      m(r, c) = x;
    }
  if (std::abs(m(3, 0)) > 1e-9 || std::abs(m(3, 1)) > 1e-9 || std::abs(m(3, 2)) > 1e-9 ||
      std::abs(m(3, 3) - 1) > 1e-9)
    return absl::InvalidArgumentError(absl::StrCat(what, ": last row must be 0 0 0 1"));
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  const double ortho_error = (r.transpose() * r - Eigen::Matrix3d::Identity()).norm();
  if (ortho_error > 1e-6 || r.determinant() < 0)
    return absl::InvalidArgumentError(
        absl::StrCat(what, ": upper-left 3x3 is not a rotation (|R^T R - I| = ", ortho_error,
                     ", det = ", r.determinant(), ")"));
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  // Re-orthonormalise only what needs it: a matrix that is already a
  // rotation to rounding keeps its exact bits (so a transform survives
  // file and wire round trips unchanged).
  t.linear() = ortho_error > 1e-12 ? Eigen::Quaterniond(r).normalized().toRotationMatrix() : r;
  t.translation() = m.topRightCorner<3, 1>();
  return t;
}

PointCloud TransformCloud(const PointCloud& cloud, const Eigen::Isometry3d& to_from) {
  PointCloud out = cloud;
  for (auto& p : out.points)
    if (PointCloud::IsValid(p)) p = (to_from * p.cast<double>()).cast<float>();
  return out;
}

bool TransformKeepsCloud(const PointCloud& cloud, const Eigen::Isometry3d& to_from) {
  if (to_from.matrix() != Eigen::Matrix4d::Identity()) return false;
  // -0 is the one float whose bits are 0x80000000 (a NaN pixel never is).
  static_assert(sizeof(Eigen::Vector3f) == 12, "points are three packed floats");
  if (cloud.points.empty()) return true;
  return !AnyFloatWithBits(cloud.points[0].data(), 3 * cloud.points.size(), 0xffffffffu,
                           0x80000000u);
}

PoseDifference ComparePoses(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  const Eigen::Isometry3d d = a.inverse() * b;
  const Eigen::AngleAxisd aa(d.linear());
  return {d.translation().norm(), std::abs(aa.angle()) * 180.0 / M_PI};
}

}  // namespace surfinspect
