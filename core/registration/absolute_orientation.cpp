#include "core/registration/absolute_orientation.h"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace surfinspect {

absl::StatusOr<Eigen::Isometry3d> HornAbsoluteOrientation(const std::vector<Eigen::Vector3d>& from,
                                                          const std::vector<Eigen::Vector3d>& to,
                                                          const std::vector<double>& weights) {
  const std::size_t n = from.size();
  if (to.size() != n || (!weights.empty() && weights.size() != n))
    return absl::InvalidArgumentError("absolute orientation: point sets differ in size");
  if (n < 3) return absl::InvalidArgumentError("absolute orientation: need at least 3 pairs");
  auto w = [&](std::size_t i) { return weights.empty() ? 1.0 : weights[i]; };

  // Centroids (Horn §2.C): the translation follows from them.
  double wsum = 0;
  Eigen::Vector3d ca = Eigen::Vector3d::Zero(), cb = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    if (!from[i].allFinite() || !to[i].allFinite() || !(w(i) >= 0) || !std::isfinite(w(i)))
      return absl::InvalidArgumentError("absolute orientation: non-finite point or weight");
    wsum += w(i);
    ca += w(i) * from[i];
    cb += w(i) * to[i];
  }
  if (!(wsum > 0)) return absl::InvalidArgumentError("absolute orientation: all weights are zero");
  ca /= wsum;
  cb /= wsum;

  // Cross-covariance M = sum w (a - ca)(b - cb)^T, entries S_xy (Horn eq. 30 ff).
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  double spread = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d a = from[i] - ca;
    m += w(i) * a * (to[i] - cb).transpose();
    spread += w(i) * a.squaredNorm();
  }
  const double sxx = m(0, 0), sxy = m(0, 1), sxz = m(0, 2), syx = m(1, 0), syy = m(1, 1),
               syz = m(1, 2), szx = m(2, 0), szy = m(2, 1), szz = m(2, 2);
  // The symmetric 4x4 N whose top eigenvector is the optimal unit quaternion.
  Eigen::Matrix4d nm;
  nm << sxx + syy + szz, syz - szy, szx - sxz, sxy - syx, syz - szy, sxx - syy - szz, sxy + syx,
      szx + sxz, szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy, sxy - syx, szx + sxz, syz + szy,
      -sxx - syy + szz;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eig(nm);
  const Eigen::Vector4d ev = eig.eigenvalues();
  // Collinear (or coincident) points leave a rotation about the line free:
  // the two largest eigenvalues of N then coincide.
  if (!(spread > 0) || ev(3) - ev(2) <= 1e-12 * std::max(1.0, std::abs(ev(3))))
    return absl::InvalidArgumentError("absolute orientation: degenerate (collinear) points");
  const Eigen::Vector4d q = eig.eigenvectors().col(3);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::Quaterniond(q(0), q(1), q(2), q(3)).normalized().toRotationMatrix();
  t.translation() = cb - t.linear() * ca;
  return t;
}

}  // namespace surfinspect
