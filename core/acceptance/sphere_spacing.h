// Sphere-spacing error of a ball bar (VDI/VDE 2634 Part 2, §6.3; Part 3 for
// spheres seen from different viewpoints): SD = fitted centre distance -
// calibrated length, from two probing-error fits (probing_error.h). Its
// standard uncertainty (k = 1) combines, along the bar's direction u:
//   the two fits' centre covariances;
//   the calibrations of the viewpoints that saw the spheres, propagated to
//   each centre (pose_covariance.h). When both spheres come from one view,
//   one rigid pose error moves both and keeps their distance: the Jacobians
//   are subtracted before the covariance is applied, which leaves 0 (to
//   first order), so only cross-view positions test the calibration;
//   the ball bar's own calibration uncertainty.
#pragma once

#include <Eigen/Geometry>

#include "core/acceptance/pose_covariance.h"
#include "core/acceptance/probing_error.h"

namespace surfinspect {

// The calibration of the viewpoint a sphere was seen from.
struct ViewCalibrationUncertainty {
  Eigen::Isometry3d world_from_gauge = Eigen::Isometry3d::Identity();
  PoseCovariance covariance = PoseCovariance::Zero();
};

struct SphereSpacing {
  double length_mm = 0;  // distance of the two fitted centres
  double sd_mm = 0;      // length - calibrated length
  double u_sd_mm = 0;    // sqrt(u_fit^2 + u_calibration^2 + u_artefact^2)
  double u_fit_mm = 0, u_calibration_mm = 0, u_artefact_mm = 0;
};

SphereSpacing ComputeSphereSpacing(const ProbingError& a, const ViewCalibrationUncertainty& view_a,
                                   const ProbingError& b, const ViewCalibrationUncertainty& view_b,
                                   bool same_view, double calibrated_length_mm, double u_length_mm);

}  // namespace surfinspect
