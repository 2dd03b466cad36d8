#include "core/types/point_cloud.h"

#include <cstdint>
#include <cstring>

#include "absl/strings/str_cat.h"
#include "core/types/float_scan.h"

namespace surfinspect {

PointCloud PointCloud::Unorganized(std::vector<Eigen::Vector3f> pts) {
  PointCloud c;
  c.width = static_cast<uint32_t>(pts.size());
  c.height = 1;
  c.points = std::move(pts);
  return c;
}

PointCloud PointCloud::Organized(uint32_t width, uint32_t height) {
  PointCloud c;
  c.width = width;
  c.height = height;
  c.points.assign(static_cast<std::size_t>(width) * height, Eigen::Vector3f::Constant(NAN));
  return c;
}

std::size_t PointCloud::CountValid() const {
  std::size_t n = 0;
  for (const auto& p : points) n += IsValid(p) ? 1 : 0;
  return n;
}

absl::Status PointCloud::Validate() const {
  if (static_cast<std::size_t>(width) * height != points.size())
    return absl::InvalidArgumentError(absl::StrCat("cloud: width*height = ", width, "*", height,
                                                   " does not match ", points.size(), " points"));
  return ValidatePoints(0, points.size());
}

namespace {

// Whether any of the n floats is infinite: its bits with the sign cleared
// are exactly the exponent's.
bool AnyInfinite(const float* f, std::size_t n) {
  return AnyFloatWithBits(f, n, 0x7fffffffu, 0x7f800000u);
}

}  // namespace

absl::Status PointCloud::ValidatePoints(std::size_t first, std::size_t last) const {
  static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float), "points are packed floats");
  if (first >= last || !AnyInfinite(points[first].data(), 3 * (last - first)))
    return absl::OkStatus();
  // The point-by-point pass names the first infinite one.
  for (std::size_t i = first; i < last; ++i) {
    const auto& p = points[i];
    if (IsValid(p)) continue;
    for (int k = 0; k < 3; ++k)
      if (std::isinf(p[k]))
        return absl::InvalidArgumentError(
            absl::StrCat("cloud: point ", i, " has an infinite coordinate"));
  }
  return absl::OkStatus();
}

Bounds3 ComputeBounds(const PointCloud& cloud) {
  Bounds3 b;
  cloud.ForEachValid([&](std::size_t, const Eigen::Vector3f& p) { b.Extend(p.cast<double>()); });
  return b;
}

}  // namespace surfinspect
