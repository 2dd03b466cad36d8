// A least-squares fit of an isotropic Gaussian bump on a plane,
//   f(u, v) = c + A exp(-|(u, v) - x0|^2 / (2 s^2)),
// by Levenberg-Marquardt (Marquardt, "An algorithm for least-squares
// estimation of nonlinear parameters", SIAM J. Appl. Math. 1963) over the
// parameters (A, u0, v0, ln s, c): ln s keeps s > 0. Used for a defect's
// peak (core/plan/defects.h); units are the caller's (mm here).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace surfinspect {

struct GaussianFit {
  bool ok = false;  // finite parameters from at least 8 samples
  double amplitude = 0, baseline = 0, sigma = 1, rms = 0;  // A, c, s; RMS residual
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();        // (u0, v0)
};

// Samples (u, v, value); `keep[k]` != 0 selects sample k (same size).
// `start` is the first guess (sigma > 0). At most 50 iterations; stops when
// the cost falls by less than 1e-12 relative.
GaussianFit FitIsotropicGaussian(const std::vector<Eigen::Vector3d>& uvd,
                                 const std::vector<char>& keep, const GaussianFit& start);

}  // namespace surfinspect
