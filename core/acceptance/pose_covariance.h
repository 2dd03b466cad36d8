// How a viewpoint calibration's uncertainty reaches a scanned point. The
// calibration (core/registration/calibration.h) reports the covariance of
// x = [w (rad), t (mm)], the left perturbation of gauge_from_sensor in the
// gauge frame: gauge_from_sensor' = exp(x) gauge_from_sensor. A point seen by
// the sensor lands in the world at p = world_from_gauge * q with q in the
// gauge frame, so it moves by dp = R_wg (w x q + t) = R_wg [-[q]x, I] x.
#pragma once

#include <Eigen/Geometry>

namespace surfinspect {

using PoseCovariance = Eigen::Matrix<double, 6, 6>;

// d p_world / d x at the world point `p_world` (mm per rad, mm per mm).
Eigen::Matrix<double, 3, 6> WorldPointJacobian(const Eigen::Isometry3d& world_from_gauge,
                                               const Eigen::Vector3d& p_world);

// J C J^T: the 3x3 covariance (mm^2, world axes) of `p_world` from the
// calibration covariance C.
Eigen::Matrix3d WorldPointCovariance(const Eigen::Isometry3d& world_from_gauge,
                                     const PoseCovariance& covariance,
                                     const Eigen::Vector3d& p_world);

}  // namespace surfinspect
