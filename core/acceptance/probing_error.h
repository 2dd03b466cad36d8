// Probing errors of a sphere (VDI/VDE 2634 Part 2, §6.2): the sphere's
// points are found near their hinted centre in a world-frame cloud, fitted
// by least squares (core/acceptance/sphere_fit.h) with a free radius, and
//   PF = range of the radial residuals (largest minus smallest), after
//        leaving out the `outlier_share` of points with the largest |residual|;
//   PS = fitted diameter - calibrated diameter.
// Units mm, world frame. Uncertainties are standard (k = 1): the fit's
// covariance (and, for PF, how finely the points resolve the extremes:
// ExtremeResolution; for PS the artefact's calibration, added by the
// caller); a rigid calibration error moves the sphere but changes neither.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/acceptance/sphere_fit.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

struct SphereSearch {
  Eigen::Vector3d centre_hint_mm = Eigen::Vector3d::Zero();  // world
  double diameter_mm = 25;                                   // calibrated
  double search_mm = 5;          // the true centre is within this of the hint
  double band_mm = 0.5;          // kept: |radial residual of the first fit| <= band
  std::size_t min_points = 200;  // fewer found: the sphere is not in the scan
};

struct ProbingError {
  SphereFit fit;                                       // on the kept points
  std::size_t candidates = 0, kept = 0, left_out = 0;  // left_out: outlier_share of kept
  double pf_mm = 0, u_pf_mm = 0;
  double diameter_mm = 0, ps_mm = 0, u_ps_mm = 0;               // u_ps without the artefact's own u
  Eigen::Matrix3d centre_covariance = Eigen::Matrix3d::Zero();  // mm^2
};

// Selects, fits and evaluates. NotFound "<what>: N points near (x, y, z): the
// sphere is not in the scan" when fewer than min_points are found;
// InvalidArgument for a bad search or a fit that fails.
absl::StatusOr<ProbingError> MeasureSphere(const PointCloud& cloud_in_world,
                                           const SphereSearch& search, double outlier_share,
                                           const std::string& what);

// The range of `residuals` after leaving out the ceil(share * n) largest
// |residual| (indices of the kept extremes in *lo / *hi).
double TrimmedRange(const std::vector<double>& residuals, double share, std::size_t* lo,
                    std::size_t* hi, std::size_t* left_out);

// How finely the sample resolves the extremes of a trimmed range: the mean
// gap between residuals[i] and its neighbours in value (all residuals), for
// i = lo and hi, combined as sqrt(g_lo^2 + g_hi^2). In the sparse tails of
// noisy residuals which point is left out moves the range by about this
// much, a standard-uncertainty term of PF and F beside the fit's.
double ExtremeResolution(const std::vector<double>& residuals, std::size_t lo, std::size_t hi);

}  // namespace surfinspect
