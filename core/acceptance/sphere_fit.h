// Least-squares (Gaussian) sphere fit: the centre c and radius r that
// minimise sum_i (|p_i - c| - r)^2, the geometric distance of each point to
// the sphere. Gauss-Newton from the algebraic (linear) fit, as in Forbes,
// "Least-squares best-fit geometric elements", NPL Report DITC 140/89
// (1989), §3.5, and Shakarji, "Least-squares fitting algorithms of the NIST
// algorithm testing system", J. Res. NIST 103 (1998), §3.6; ISO 10360-6
// tests implementations of exactly this fit. Units are the caller's (mm).
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "absl/status/statusor.h"

namespace surfinspect {

struct SphereFit {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0;
  double rms = 0;                 // RMS of the signed radial residuals |p - c| - r
  std::vector<double> residuals;  // per point, same order as the input
  // Covariance of [c, r] from the final normal equations, s^2 (J^T J)^-1,
  // with s^2 = sum res^2 / (n - 4) (Forbes §2.3): the fit's own uncertainty
  // for independent point errors.
  Eigen::Matrix4d covariance = Eigen::Matrix4d::Zero();
  int iterations = 0;
  bool converged = false;  // the last step moved c and r by < 1e-9 mm
};

// At least 10 points (4 parameters, and a usable residual variance).
// InvalidArgument for fewer points or points that do not fix a sphere (all on
// a plane or a line: singular normal equations).
absl::StatusOr<SphereFit> FitSphere(const std::vector<Eigen::Vector3d>& points);

}  // namespace surfinspect
