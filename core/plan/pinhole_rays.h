// The rays of an organized view's pixels, fitted from the cloud itself: in
// the sensor frame a pinhole camera sits at the origin and the point of
// pixel (col, row) lies on the ray through (a, b, 1) with x/z = a and
// y/z = b affine in (col, row) (any focal lengths, principal point and
// skew; no lens distortion: a structured-light sensor's clouds come
// rectified). Noise
// along the ray leaves x/z and y/z unchanged, so the fit is as sharp as the
// grid. A pixel without a point still has its ray: that is what locates an
// edge between a point and no data (core/plan/holes.h).
#pragma once

#include <Eigen/Core>

#include "absl/status/statusor.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

struct PinholeRays {
  Eigen::Matrix<double, 2, 3> affine = Eigen::Matrix<double, 2, 3>::Zero();
  double sign = 1;      // z of the points in front of the sensor
  double rms_px = NAN;  // the fit's residual, in pixels
  Eigen::Vector3d Direction(double col, double row) const {
    const Eigen::Vector2d ab = affine * Eigen::Vector3d(col, row, 1);
    return sign * Eigen::Vector3d(ab.x(), ab.y(), 1);
  }
};
// InvalidArgument for a grid with too few valid points or rays that are not
// a pinhole's (residual above half a pixel).
absl::StatusOr<PinholeRays> FitPinholeRays(const PointCloud& grid_in_sensor);

// The pixel (col, row) whose ray passes through p (sensor frame), false
// behind the sensor.
bool ProjectToPixel(const PinholeRays& rays, const Eigen::Vector3d& p, Eigen::Vector2d* pixel);

}  // namespace surfinspect
