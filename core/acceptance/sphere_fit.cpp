#include "core/acceptance/sphere_fit.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

constexpr std::size_t kMinPoints = 10;
constexpr int kMaxIterations = 50;

// The algebraic fit |p|^2 = 2 c.p + (r^2 - |c|^2), linear in (c, k), solved
// about the centroid for conditioning (Forbes §3.5.1).
absl::StatusOr<Eigen::Vector4d> AlgebraicStart(const std::vector<Eigen::Vector3d>& pts) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : pts) mean += p;
  mean /= double(pts.size());
  Eigen::Matrix4d ata = Eigen::Matrix4d::Zero();
  Eigen::Vector4d atb = Eigen::Vector4d::Zero();
  for (const auto& p : pts) {
    const Eigen::Vector3d q = p - mean;
    const Eigen::Vector4d row(2 * q.x(), 2 * q.y(), 2 * q.z(), 1.0);
    ata += row * row.transpose();
    atb += row * q.squaredNorm();
  }
  const Eigen::FullPivLU<Eigen::Matrix4d> lu(ata);
  if (!lu.isInvertible())
    return absl::InvalidArgumentError("sphere fit: the points do not fix a sphere");
  const Eigen::Vector4d x = lu.solve(atb);
  const double r2 = x(3) + x.head<3>().squaredNorm();
  if (!(r2 > 0)) return absl::InvalidArgumentError("sphere fit: the points do not fix a sphere");
  Eigen::Vector4d start;
  start << x.head<3>() + mean, std::sqrt(r2);
  return start;
}

}  // namespace

absl::StatusOr<SphereFit> FitSphere(const std::vector<Eigen::Vector3d>& pts) {
  if (pts.size() < kMinPoints)
    return absl::InvalidArgumentError(
        absl::StrCat("sphere fit: ", pts.size(), " points; at least ", kMinPoints, " needed"));
  ASSIGN_OR_RETURN(auto start, AlgebraicStart(pts));
  SphereFit f;
  f.centre = start.head<3>();
  f.radius = (start)(3);
  Eigen::Matrix4d jtj;
  // Gauss-Newton on d_i = |p_i - c| - r with J_i = [-(p_i - c)^T / |p_i - c|, -1]
  // (Forbes §3.5.2, Shakarji §3.6).
  for (f.iterations = 1; f.iterations <= kMaxIterations; ++f.iterations) {
    jtj.setZero();
    Eigen::Vector4d jtd = Eigen::Vector4d::Zero();
    for (const auto& p : pts) {
      const Eigen::Vector3d v = p - f.centre;
      const double len = v.norm();
      if (!(len > 0)) continue;
      Eigen::Vector4d j;
      j << -v / len, -1.0;
      jtj += j * j.transpose();
      jtd += j * (len - f.radius);
    }
    const Eigen::LDLT<Eigen::Matrix4d> ldlt(jtj);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0))
      return absl::InvalidArgumentError("sphere fit: the points do not fix a sphere");
    const Eigen::Vector4d step = -ldlt.solve(jtd);
    f.centre += step.head<3>();
    f.radius += step(3);
    if (step.norm() < 1e-9) {
      f.converged = true;
      break;
    }
  }
  if (!(f.radius > 0) || !f.centre.allFinite())
    return absl::InvalidArgumentError("sphere fit: did not converge to a sphere");
  double sum2 = 0;
  f.residuals.reserve(pts.size());
  for (const auto& p : pts) {
    f.residuals.push_back((p - f.centre).norm() - f.radius);
    sum2 += f.residuals.back() * f.residuals.back();
  }
  f.rms = std::sqrt(sum2 / double(pts.size()));
  f.covariance = (sum2 / double(pts.size() - 4)) * jtj.inverse();
  return f;
}

}  // namespace surfinspect
