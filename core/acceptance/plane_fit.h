// Least-squares (Gaussian) plane fit: the plane through the centroid whose
// normal is the eigenvector of the smallest eigenvalue of the points'
// scatter matrix, which minimises the sum of squared orthogonal distances
// (Forbes, NPL Report DITC 140/89 (1989), §3.2; Shakarji, J. Res. NIST 103
// (1998), §3.2; the ISO 10360-6 reference fit). Units are the caller's (mm).
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "absl/status/statusor.h"

namespace surfinspect {

struct PlaneFit {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();    // the centroid, on the plane
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit; sign: normal.z() >= 0
  double rms = 0;                                     // RMS orthogonal residual
  std::vector<double> residuals;                      // signed, normal . (p - point)
  // The in-plane axes (eigenvectors of the two larger eigenvalues) and the
  // variance of the normal's tilt towards each, s^2 / lambda_k, with
  // s^2 = sum res^2 / (n - 3) and lambda_k the scatter along axis k: the
  // fit's own uncertainty for independent point errors.
  Eigen::Vector3d axis1 = Eigen::Vector3d::UnitX(), axis2 = Eigen::Vector3d::UnitY();
  double tilt_variance1 = 0, tilt_variance2 = 0;  // rad^2
  double offset_variance = 0;                     // of the plane along its normal, mm^2
};

// At least 10 points. InvalidArgument for fewer, or for points on a line.
absl::StatusOr<PlaneFit> FitPlane(const std::vector<Eigen::Vector3d>& points);

}  // namespace surfinspect
