#include "core/io/unit_doubt.h"

#include <cmath>

#include "absl/strings/str_format.h"

namespace surfinspect {

Extent ExtentOf(const PointCloud& cloud) {
  const Bounds3 b = ComputeBounds(cloud);
  return {b.empty() ? 0.0 : (b.max - b.min).norm(), cloud.CountValid(), true};
}

Extent ExtentOf(const TriangleMesh& mesh) {
  const Bounds3 b = ComputeBounds(mesh);
  return {b.empty() ? 0.0 : (b.max - b.min).norm(), mesh.num_triangles(), false};
}

std::string SizeDoubt(const UnitSubject& s) {
  const Extent& e = s.extent;
  const std::size_t enough = e.points ? kMinPointsForSize : kMinTrianglesForSize;
  if (s.stated || e.items < enough || e.diagonal <= 0 || e.diagonal >= kSmallestPartMm) return "";
  // Metres first: the PCL and ROS convention, and what every real sensor
  // file tried here was in; inches second.
  return absl::StrFormat(
      "%s: %d %s span only %.3g mm if they are millimetres, implausible for a part; they look "
      "like metres (%.4g mm across) or inches (%.4g mm): state the unit with %s m (or in), or "
      "%s mm if the part really is this small",
      s.what, e.items, e.points ? "points" : "triangles", e.diagonal, e.diagonal * 1000,
      e.diagonal * 25.4, s.option, s.option);
}

std::string RatioDoubt(const UnitSubject& cloud, const UnitSubject& mesh) {
  if (cloud.stated && mesh.stated) return "";
  const double c = cloud.extent.diagonal, m = mesh.extent.diagonal;
  if (c <= 0 || m <= 0) return "";
  const double ratio = c > m ? c / m : m / c;
  if (ratio <= kLargestSizeRatio) return "";
  const UnitSubject& small = c < m ? cloud : mesh;
  const UnitSubject& large = c < m ? mesh : cloud;
  const UnitSubject& unstated = small.stated ? large : small;
  return absl::StrFormat(
      "%s spans %.4g mm and %s %.4g mm: %.0f times apart, so one of them is likely in another "
      "unit (metres against millimetres is 1000): state it with %s <unit>",
      cloud.what, c, mesh.what, m, ratio, unstated.option);
}

std::vector<std::string> UnitDoubts(const UnitSubject& cloud, const UnitSubject* mesh) {
  std::vector<std::string> doubts;
  for (const UnitSubject* s : {&cloud, mesh})
    if (s)
      if (std::string d = SizeDoubt(*s); !d.empty()) doubts.push_back(std::move(d));
  if (doubts.empty() && mesh)
    if (std::string d = RatioDoubt(cloud, *mesh); !d.empty()) doubts.push_back(std::move(d));
  return doubts;
}

}  // namespace surfinspect
