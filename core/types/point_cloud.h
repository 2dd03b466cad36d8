// PointCloud: float32 xyz points in millimetres, optionally organized as a
// width x height sensor grid (row-major, index = row * width + col) where a
// pixel without a valid measurement holds NaN coordinates.
//
// The frame of the points is not stored; callers name it in their variables
// (`cloud_in_sensor`, `cloud_in_world`). An unorganized cloud has height == 1
// and width == size(), as in PCL.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "absl/status/status.h"

namespace surfinspect {

struct PointCloud {
  std::vector<Eigen::Vector3f> points;  // mm
  uint32_t width = 0;                   // grid columns (or size() if unorganized)
  uint32_t height = 0;                  // grid rows (1 if unorganized)

  static PointCloud Unorganized(std::vector<Eigen::Vector3f> pts);
  static PointCloud Organized(uint32_t width, uint32_t height);  // all NaN

  std::size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
  bool organized() const { return height > 1; }

  // A point is valid when all three coordinates are finite.
  static bool IsValid(const Eigen::Vector3f& p) {
    return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z());
  }
  std::size_t CountValid() const;

  // Calls f(index, point) for every valid point, in storage order.
  template <typename F>
  void ForEachValid(F&& f) const {
    for (std::size_t i = 0; i < points.size(); ++i)
      if (IsValid(points[i])) f(i, points[i]);
  }

  // Checks width * height == size(). Coordinates may be NaN (no data) but a
  // point with one finite and one infinite coordinate is rejected.
  absl::Status Validate() const;
  // The coordinate check alone, on points [first, last) (last <= size()),
  // for clouds filled piece by piece.
  absl::Status ValidatePoints(std::size_t first, std::size_t last) const;
};

// Axis-aligned bounds of the valid points; empty() when there are none.
struct Bounds3 {
  Eigen::Vector3d min{Eigen::Vector3d::Constant(INFINITY)};
  Eigen::Vector3d max{Eigen::Vector3d::Constant(-INFINITY)};
  bool empty() const { return !(min.x() <= max.x()); }
  void Extend(const Eigen::Vector3d& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
};
Bounds3 ComputeBounds(const PointCloud& cloud);

}  // namespace surfinspect
