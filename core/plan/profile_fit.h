// Least-squares (Gaussian) fits of a hole's profile in its plane: a circle,
// or a slot (a stadium: two half circles joined by straight sides). Both
// minimise the sum of squared geometric distances from the points to the
// contour, by Gauss-Newton from an algebraic (circle) or principal-axes
// (slot) start, as in Forbes, "Least-squares best-fit geometric elements",
// NPL Report DITC 140/89 (1989), §3.4, and Shakarji, J. Res. NIST 103
// (1998), §3.5. Robust rejection: after each fit, points farther than
// kRejectSigmas robust sigmas (1.4826 MAD of the residuals) from the contour
// are left out and the fit is repeated until the inlier set holds still, so
// a burr, a stray point or a pixel of the wall below does not pull the fit.
// Units are the caller's (mm).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"

namespace surfinspect {

inline constexpr double kRejectSigmas = 3.0;

struct ProfileFit {
  bool slot = false;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  Eigen::Vector2d direction = Eigen::Vector2d::UnitX();  // slot: along its length (unit)
  double radius = 0;                                     // the circle's; a slot's half width
  double half_length = 0;         // slot: half the distance between its end centres; 0 for a circle
  double rms = 0;                 // of the inliers' residuals
  double form = 0;                // max - min residual of the inliers (ISO 1101 form, as fitted)
  std::vector<double> residuals;  // per point: signed distance to the contour (+ outside)
  std::vector<uint8_t> inlier;    // per point: 1 when kept by the robust rejection
  std::size_t inliers = 0;
  bool converged = false;
  double diameter() const { return 2 * radius; }
  double length() const { return 2 * (half_length + radius); }  // a slot's overall length
};

// A nominal contour centred at the origin along +x: a circle of `diameter`,
// or a slot of that width and overall `length` (slot only).
ProfileFit NominalContour(bool slot, double diameter, double length);

// Signed distance from q to the contour of `fit` (+ outside the hole).
double ProfileDistance(const ProfileFit& fit, const Eigen::Vector2d& q);

// At least 6 points. InvalidArgument when the points do not fix a circle
// (collinear) or the fit does not converge.
absl::StatusOr<ProfileFit> FitCircle2d(const std::vector<Eigen::Vector2d>& points);

// At least 10 points. `start` gives the nominal slot (centre, direction,
// radius, half_length) the fit begins from; the points must go round it.
absl::StatusOr<ProfileFit> FitSlot2d(const std::vector<Eigen::Vector2d>& points,
                                     const ProfileFit& start);

}  // namespace surfinspect
