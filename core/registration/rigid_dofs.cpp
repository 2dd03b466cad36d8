#include "core/registration/rigid_dofs.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "absl/strings/str_join.h"

namespace surfinspect {
namespace {

Eigen::Matrix3d RotationX(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Eigen::Matrix3d r;
  r << 1, 0, 0, 0, c, -s, 0, s, c;
  return r;
}
Eigen::Matrix3d RotationY(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Eigen::Matrix3d r;
  r << c, 0, s, 0, 1, 0, -s, 0, c;
  return r;
}
Eigen::Matrix3d RotationZ(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Eigen::Matrix3d r;
  r << c, -s, 0, s, c, 0, 0, 0, 1;
  return r;
}

// Reduced row echelon form of the rows of `basis` (k x 6) with complete
// pivoting, so that each row is led by the DOF it moves most; returns the
// pivot DOF of each row. Rows span the same space as before.
std::vector<int> EchelonRows(Eigen::Matrix<double, Eigen::Dynamic, kRigidDofs>& basis) {
  const int k = static_cast<int>(basis.rows());
  std::vector<int> pivots;
  std::vector<bool> used(kRigidDofs, false);
  for (int s = 0; s < k; ++s) {
    int best_row = s, best_col = -1;
    double best = -1;
    for (int r = s; r < k; ++r)
      for (int c = 0; c < kRigidDofs; ++c)
        if (!used[c] && std::abs(basis(r, c)) > best) {
          best = std::abs(basis(r, c));
          best_row = r;
          best_col = c;
        }
    basis.row(s).swap(basis.row(best_row));
    basis.row(s) /= basis(s, best_col);
    for (int r = 0; r < k; ++r)
      if (r != s) basis.row(r) -= basis(r, best_col) * basis.row(s);
    used[best_col] = true;
    pivots.push_back(best_col);
  }
  return pivots;
}

// "rotation about z", or "translation along y with rotation about z": the
// pivot first, then every DOF within 0.2 of the row's largest component.
std::string DescribeMotion(const RigidParams& row, int pivot) {
  const double largest = row.cwiseAbs().maxCoeff();
  std::vector<std::string> parts = {DofName(pivot)};
  for (int c = 0; c < kRigidDofs; ++c)
    if (c != pivot && std::abs(row[c]) >= 0.2 * largest) parts.push_back(DofName(c));
  return absl::StrJoin(parts, " with ");
}

}  // namespace

const char* DofName(int dof) {
  switch (dof) {
    case kTx:
      return "translation along x";
    case kTy:
      return "translation along y";
    case kTz:
      return "translation along z";
    case kRx:
      return "rotation about x";
    case kRy:
      return "rotation about y";
    case kRz:
      return "rotation about z";
  }
  return "unknown";
}

bool LockedDofs::IsLocked(int dof) const {
  const bool all[kRigidDofs] = {tx, ty, tz, rx, ry, rz};
  return dof >= 0 && dof < kRigidDofs && all[dof];
}

int LockedDofs::FreeCount() const {
  int n = 0;
  for (int d = 0; d < kRigidDofs; ++d) n += IsLocked(d) ? 0 : 1;
  return n;
}

RigidMotion::RigidMotion(const RigidParams& x) {
  rx_ = RotationX(x[kRx]);
  zy_ = RotationZ(x[kRz]) * RotationY(x[kRy]);
  transform_ = Eigen::Isometry3d::Identity();
  transform_.linear() = zy_ * rx_;
  transform_.translation() = x.head<3>();
}

Eigen::Matrix<double, 3, kRigidDofs> RigidMotion::Jacobian(const Eigen::Vector3d& p) const {
  // With R = Rz·Ry·Rx and dRa/da = Ra·[e_a]× = [e_a]×·Ra:
  //   ∂/∂rx = Rz·Ry·Rx·(e_x × p), ∂/∂ry = Rz·Ry·(e_y × Rx·p), ∂/∂rz = e_z × R·p.
  const Eigen::Vector3d xp = rx_ * p;
  const Eigen::Vector3d rp = zy_ * xp;
  Eigen::Matrix<double, 3, kRigidDofs> j;
  j.leftCols<3>().setIdentity();
  j.col(kRx) = transform_.linear() * Eigen::Vector3d(0, -p.z(), p.y());
  j.col(kRy) = zy_ * Eigen::Vector3d(xp.z(), 0, -xp.x());
  j.col(kRz) = Eigen::Vector3d(-rp.y(), rp.x(), 0);
  return j;
}

RigidParams ParamsFromTransform(const Eigen::Isometry3d& t) {
  // R = Rz·Ry·Rx has R(2,0) = −sin ry, R(2,1) / R(2,2) = tan rx, R(1,0) / R(0,0) = tan rz.
  const Eigen::Matrix3d& r = t.linear();
  RigidParams x;
  x.head<3>() = t.translation();
  x[kRy] = std::asin(std::clamp(-r(2, 0), -1.0, 1.0));
  x[kRx] = std::atan2(r(2, 1), r(2, 2));
  x[kRz] = std::atan2(r(1, 0), r(0, 0));
  return x;
}

RigidParams ScaledAnalysisRow(const Eigen::Vector3d& p_mm, const Eigen::Vector3d& d,
                              const Eigen::Vector3d& centre_mm, double length_mm) {
  RigidParams row;
  row << d, (p_mm - centre_mm).cross(d) / length_mm;
  return row;
}

DofAnalysis AnalyseDofs(const DofMatrix& scaled_normal, const LockedDofs& locked) {
  DofAnalysis out;
  std::vector<int> free_dofs;
  for (int d = 0; d < kRigidDofs; ++d)
    if (!locked.IsLocked(d)) free_dofs.push_back(d);
  const int m = static_cast<int>(free_dofs.size());
  if (m == 0) return out;
  Eigen::MatrixXd block(m, m);
  for (int a = 0; a < m; ++a)
    for (int b = 0; b < m; ++b) block(a, b) = scaled_normal(free_dofs[a], free_dofs[b]);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(block);
  const Eigen::VectorXd& lambda = eig.eigenvalues();  // ascending
  const double largest = lambda[m - 1];
  const double cut = kFreeDofRelativeEigenvalue * largest;
  std::vector<int> null_columns;
  for (int i = 0; i < m; ++i)
    if (!(largest > 0) || lambda[i] < cut) null_columns.push_back(i);
  out.condition = null_columns.empty() ? largest / lambda[0] : INFINITY;
  if (null_columns.empty()) return out;

  Eigen::Matrix<double, Eigen::Dynamic, kRigidDofs> basis(null_columns.size(), kRigidDofs);
  basis.setZero();
  for (std::size_t r = 0; r < null_columns.size(); ++r)
    for (int a = 0; a < m; ++a) basis(r, free_dofs[a]) = eig.eigenvectors()(a, null_columns[r]);
  const std::vector<int> pivots = EchelonRows(basis);
  std::vector<int> order(pivots.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return pivots[a] < pivots[b]; });
  for (int r : order) out.free.push_back(DescribeMotion(basis.row(r).transpose(), pivots[r]));
  return out;
}

std::string JoinFree(const std::vector<std::string>& free) { return absl::StrJoin(free, ", "); }

}  // namespace surfinspect
