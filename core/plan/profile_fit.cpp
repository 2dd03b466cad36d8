#include "core/plan/profile_fit.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <functional>

#include "absl/strings/str_cat.h"
#include "core/plan/surface_neighbourhood.h"

namespace surfinspect {
namespace {

constexpr int kMaxIterations = 60;
constexpr int kMaxRejectionRounds = 8;

using Params = Eigen::VectorXd;
// Residual of one point and its gradient with respect to the parameters.
using ResidualFn = std::function<double(const Params&, const Eigen::Vector2d&, Eigen::VectorXd*)>;

// Slot parameters: centre (2), angle of the direction, half_length, radius.
ProfileFit SlotOf(const Params& x) {
  ProfileFit f;
  f.slot = true;
  f.centre = x.head<2>();
  f.direction = {std::cos(x(2)), std::sin(x(2))};
  f.half_length = x(3);
  f.radius = x(4);
  return f;
}

// d = |p - s| - rho with s the closest point of the slot's centre segment;
// the gradient follows from n = (p - s)/|p - s| being normal to the segment
// wherever the segment's point is not an end (derivation in the .h's source).
double SlotResidual(const Params& x, const Eigen::Vector2d& p, Eigen::VectorXd* grad) {
  const Eigen::Vector2d e(std::cos(x(2)), std::sin(x(2))), e_perp(-e.y(), e.x());
  const double h = std::max(x(3), 0.0);  // a step may try h < 0: the circle
  const double u = (p - x.head<2>()).dot(e);
  const double uc = std::clamp(u, -h, h);
  const Eigen::Vector2d v = p - x.head<2>() - uc * e;
  const double len = v.norm();
  if (grad) {
    const Eigen::Vector2d n = len > 0 ? Eigen::Vector2d(v / len) : e_perp;
    grad->resize(5);
    (*grad) << -n.x(), -n.y(), -uc * n.dot(e_perp), u > h ? -n.dot(e) : (u < -h ? n.dot(e) : 0.0),
        -1.0;
  }
  return len - x(4);
}

double CircleResidual(const Params& x, const Eigen::Vector2d& p, Eigen::VectorXd* grad) {
  const Eigen::Vector2d v = p - x.head<2>();
  const double len = v.norm();
  if (grad) {
    grad->resize(3);
    if (len > 0)
      (*grad) << -v.x() / len, -v.y() / len, -1.0;
    else
      (*grad) << 0.0, 0.0, -1.0;
  }
  return len - x(2);
}

// Damped Gauss-Newton (Levenberg) over the inliers from x; false when it
// does not settle.
bool Minimise(const std::vector<Eigen::Vector2d>& pts, const std::vector<uint8_t>& inlier,
              const ResidualFn& residual, Params& x) {
  const auto n = x.size();
  double lambda = 1e-6;
  auto cost = [&](const Params& y) {
    double c = 0;
    for (std::size_t i = 0; i < pts.size(); ++i)
      if (inlier[i]) c += std::pow(residual(y, pts[i], nullptr), 2);
    return c;
  };
  double current = cost(x);
  for (int it = 0; it < kMaxIterations; ++it) {
    Eigen::MatrixXd jtj = Eigen::MatrixXd::Zero(n, n);
    Eigen::VectorXd jtd = Eigen::VectorXd::Zero(n), g;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      if (!inlier[i]) continue;
      const double d = residual(x, pts[i], &g);
      jtj += g * g.transpose();
      jtd += g * d;
    }
    for (; lambda < 1e6; lambda *= 10) {
      Eigen::MatrixXd a = jtj;
      a.diagonal() *= 1 + lambda;
      const Params step = -a.ldlt().solve(jtd);
      if (!step.allFinite()) return false;
      const Params y = x + step;
      const double next = cost(y);
      if (next <= current) {
        x = y;
        lambda = std::max(lambda / 10, 1e-9);
        if (step.norm() < 1e-10 || current - next <= 1e-14 * (1 + current)) return true;
        current = next;
        break;
      }
    }
    if (lambda >= 1e6) return true;  // no step lowers the cost: at the minimum
  }
  return false;
}

// Fits, rejects beyond kRejectSigmas robust sigmas, refits until the inliers
// hold still; fills the residuals, inliers, rms and form of `out`.
bool RobustFit(const std::vector<Eigen::Vector2d>& pts, const ResidualFn& residual,
               std::size_t min_inliers, Params& x, ProfileFit& out) {
  std::vector<uint8_t> inlier(pts.size(), 1);
  bool ok = false;
  for (int round = 0; round < kMaxRejectionRounds; ++round) {
    ok = Minimise(pts, inlier, residual, x);
    if (!ok) return false;
    std::vector<double> res(pts.size()), abs_dev;
    for (std::size_t i = 0; i < pts.size(); ++i) res[i] = residual(x, pts[i], nullptr);
    for (std::size_t i = 0; i < pts.size(); ++i)
      if (inlier[i]) abs_dev.push_back(std::abs(res[i]));
    const double sigma = MadSigma(abs_dev);
    // A floor of 1 um: an exact contour (a CAD polygon) rejects nothing.
    const double limit = std::max(kRejectSigmas * sigma, 1e-3);
    std::vector<uint8_t> next(pts.size());
    std::size_t kept = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) kept += next[i] = std::abs(res[i]) <= limit;
    out.residuals = std::move(res);
    if (kept < min_inliers || next == inlier) break;
    inlier = std::move(next);
  }
  out.inlier = inlier;
  out.inliers = 0;
  double ss = 0, lo = INFINITY, hi = -INFINITY;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (!inlier[i]) continue;
    ++out.inliers;
    ss += out.residuals[i] * out.residuals[i];
    lo = std::min(lo, out.residuals[i]);
    hi = std::max(hi, out.residuals[i]);
  }
  out.rms = std::sqrt(ss / double(std::max<std::size_t>(out.inliers, 1)));
  out.form = hi - lo;
  out.converged = ok;
  return true;
}

// Kasa's algebraic circle about the centroid (Forbes §3.4.1).
bool AlgebraicCircle(const std::vector<Eigen::Vector2d>& pts, Params& x) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : pts) mean += p;
  mean /= double(pts.size());
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d atb = Eigen::Vector3d::Zero();
  for (const auto& p : pts) {
    const Eigen::Vector2d q = p - mean;
    const Eigen::Vector3d row(2 * q.x(), 2 * q.y(), 1.0);
    ata += row * row.transpose();
    atb += row * q.squaredNorm();
  }
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(ata);
  if (!lu.isInvertible()) return false;
  const Eigen::Vector3d s = lu.solve(atb);
  const double r2 = s(2) + s.head<2>().squaredNorm();
  if (!(r2 > 0)) return false;
  x.resize(3);
  x << s.head<2>() + mean, std::sqrt(r2);
  return true;
}

}  // namespace

ProfileFit NominalContour(bool slot, double diameter, double length) {
  ProfileFit p;
  p.slot = slot;
  p.radius = 0.5 * diameter;
  p.half_length = slot ? 0.5 * (length - diameter) : 0;
  return p;
}

double ProfileDistance(const ProfileFit& fit, const Eigen::Vector2d& q) {
  Params x(5);
  x << fit.centre, std::atan2(fit.direction.y(), fit.direction.x()), fit.half_length, fit.radius;
  return SlotResidual(x, q, nullptr);
}

absl::StatusOr<ProfileFit> FitCircle2d(const std::vector<Eigen::Vector2d>& pts) {
  if (pts.size() < 6)
    return absl::InvalidArgumentError(
        absl::StrCat("circle fit: ", pts.size(), " points; at least 6 needed"));
  Params x;
  if (!AlgebraicCircle(pts, x))
    return absl::InvalidArgumentError("circle fit: the points do not fix a circle");
  ProfileFit f;
  if (!RobustFit(pts, CircleResidual, 6, x, f))
    return absl::InvalidArgumentError("circle fit: did not converge");
  f.centre = x.head<2>();
  f.radius = x(2);
  return f;
}

absl::StatusOr<ProfileFit> FitSlot2d(const std::vector<Eigen::Vector2d>& pts,
                                     const ProfileFit& start) {
  if (pts.size() < 10)
    return absl::InvalidArgumentError(
        absl::StrCat("slot fit: ", pts.size(), " points; at least 10 needed"));
  Params x(5);
  x << start.centre, std::atan2(start.direction.y(), start.direction.x()),
      std::max(start.half_length, 0.0), start.radius;
  ProfileFit f;
  if (!RobustFit(pts, SlotResidual, 10, x, f))
    return absl::InvalidArgumentError("slot fit: did not converge");
  x(3) = std::max(x(3), 0.0);  // as the residual read it
  ProfileFit shape = SlotOf(x);
  if (!(shape.radius > 0)) return absl::InvalidArgumentError("slot fit: did not converge");
  shape.residuals = std::move(f.residuals);
  shape.inlier = std::move(f.inlier);
  shape.inliers = f.inliers;
  shape.rms = f.rms;
  shape.form = f.form;
  shape.converged = f.converged;
  return shape;
}

}  // namespace surfinspect
