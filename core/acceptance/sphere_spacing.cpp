#include "core/acceptance/sphere_spacing.h"

#include <cmath>

namespace surfinspect {

SphereSpacing ComputeSphereSpacing(const ProbingError& a, const ViewCalibrationUncertainty& va,
                                   const ProbingError& b, const ViewCalibrationUncertainty& vb,
                                   bool same_view, double calibrated_length_mm,
                                   double u_length_mm) {
  SphereSpacing s;
  const Eigen::Vector3d ca = a.fit.centre, cb = b.fit.centre;
  s.length_mm = (ca - cb).norm();
  s.sd_mm = s.length_mm - calibrated_length_mm;
  const Eigen::Vector3d u = (ca - cb) / std::max(s.length_mm, 1e-12);
  // d length = u . (dc_a - dc_b).
  const double var_fit = u.dot((a.centre_covariance + b.centre_covariance) * u);
  double var_cal = 0;
  const Eigen::Matrix<double, 3, 6> ja = WorldPointJacobian(va.world_from_gauge, ca);
  const Eigen::Matrix<double, 3, 6> jb = WorldPointJacobian(vb.world_from_gauge, cb);
  if (same_view) {
    const Eigen::Matrix<double, 1, 6> g = u.transpose() * (ja - jb);
    var_cal = (g * va.covariance * g.transpose())(0, 0);
  } else {
    const Eigen::Matrix<double, 1, 6> ga = u.transpose() * ja, gb = u.transpose() * jb;
    var_cal =
        (ga * va.covariance * ga.transpose())(0, 0) + (gb * vb.covariance * gb.transpose())(0, 0);
  }
  s.u_fit_mm = std::sqrt(std::max(0.0, var_fit));
  s.u_calibration_mm = std::sqrt(std::max(0.0, var_cal));
  s.u_artefact_mm = u_length_mm;
  s.u_sd_mm = std::sqrt(s.u_fit_mm * s.u_fit_mm + s.u_calibration_mm * s.u_calibration_mm +
                        u_length_mm * u_length_mm);
  return s;
}

}  // namespace surfinspect
