#include "core/acceptance/plane_fit.h"

#include <Eigen/Eigenvalues>
#include <cmath>

#include "absl/strings/str_cat.h"

namespace surfinspect {

absl::StatusOr<PlaneFit> FitPlane(const std::vector<Eigen::Vector3d>& pts) {
  constexpr std::size_t kMinPoints = 10;
  if (pts.size() < kMinPoints)
    return absl::InvalidArgumentError(
        absl::StrCat("plane fit: ", pts.size(), " points; at least ", kMinPoints, " needed"));
  PlaneFit f;
  for (const auto& p : pts) f.point += p;
  f.point /= double(pts.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& p : pts) scatter += (p - f.point) * (p - f.point).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);
  const Eigen::Vector3d lambda = eig.eigenvalues();  // increasing
  if (!(lambda(1) > 1e-12 * std::max(lambda(2), 1e-300)))
    return absl::InvalidArgumentError("plane fit: the points lie on a line");
  f.normal = eig.eigenvectors().col(0);
  if (f.normal.z() < 0) f.normal = -f.normal;
  f.axis1 = eig.eigenvectors().col(2);
  f.axis2 = f.normal.cross(f.axis1);
  double sum2 = 0;
  f.residuals.reserve(pts.size());
  for (const auto& p : pts) {
    f.residuals.push_back(f.normal.dot(p - f.point));
    sum2 += f.residuals.back() * f.residuals.back();
  }
  const double n = double(pts.size());
  f.rms = std::sqrt(sum2 / n);
  const double s2 = sum2 / (n - 3);
  f.tilt_variance1 = s2 / lambda(2);
  f.tilt_variance2 = s2 / lambda(1);
  f.offset_variance = s2 / n;
  return f;
}

}  // namespace surfinspect
