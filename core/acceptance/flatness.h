// Flatness measurement error of a plate (VDI/VDE 2634 Part 2, §6.4): the
// plate's points inside a disc about the hinted centre are fitted by a
// least-squares plane (core/acceptance/plane_fit.h) and
//   F = range of the signed orthogonal residuals, after leaving out the
//       `outlier_share` of points with the largest |residual|.
// Units mm, world frame. Its standard uncertainty (k = 1) propagates the
// fit's normal covariance to the two extreme points (d F = -(p_hi - p_lo) .
// dn) and adds how finely the points resolve the extremes
// (ExtremeResolution, probing_error.h); the plate's calibrated flatness
// uncertainty is added by the caller.
#pragma once

#include <Eigen/Geometry>
#include <string>

#include "absl/status/statusor.h"
#include "core/acceptance/plane_fit.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

struct PlaneSearch {
  Eigen::Vector3d centre_hint_mm = Eigen::Vector3d::Zero();  // world, on the plate
  Eigen::Vector3d normal_hint = Eigen::Vector3d::UnitZ();    // unit
  double radius_mm = 40;                                     // evaluated disc, in the plane
  double search_mm = 5;  // the plate is within this of the hinted plane
  double band_mm = 0.5;  // kept: |residual of the first fit| <= band
  std::size_t min_points = 200;
};

struct Flatness {
  PlaneFit fit;  // on the kept points
  std::size_t candidates = 0, kept = 0, left_out = 0;
  double f_mm = 0, u_f_mm = 0;
};

// InvalidArgument "<what>: N points on the plate ... (at least M needed)"
// when the scan has too few plate points in the disc.
absl::StatusOr<Flatness> MeasureFlatness(const PointCloud& cloud_in_world,
                                         const PlaneSearch& search, double outlier_share,
                                         const std::string& what);

}  // namespace surfinspect
