#include "core/registration/rps_fit.h"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

// A direction is unit when its length is within this of 1: directions come
// from CAD normals and hole axes, so anything further off is a mistake.
constexpr double kUnitTolerance = 1e-6;

absl::Status ValidateReference(const RpsReference& ref, std::size_t i) {
  const std::string field =
      absl::StrCat("rps: references[", i, "]", ref.name.empty() ? "" : " (" + ref.name + ")");
  if (!ref.nominal_mm.allFinite())
    return absl::InvalidArgumentError(absl::StrCat(field, ".nominal_mm is not finite"));
  if (!ref.measured_mm.allFinite())
    return absl::InvalidArgumentError(absl::StrCat(field, ".measured_mm is not finite"));
  if (!(ref.weight > 0) || !std::isfinite(ref.weight))
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".weight must be finite and > 0, got ", ref.weight));
  const std::size_t k = ref.directions.size();
  if (k < 1 || k > 3)
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".directions must hold 1 to 3 directions, got ", k));
  Eigen::Matrix3Xd d(3, k);
  for (std::size_t j = 0; j < k; ++j) {
    const double norm = ref.directions[j].norm();
    if (!std::isfinite(norm) || std::abs(norm - 1) > kUnitTolerance)
      return absl::InvalidArgumentError(
          absl::StrCat(field, ".directions[", j, "] must be a unit vector, its length is ", norm));
    d.col(j) = ref.directions[j];
  }
  // Unit directions are independent when their Gram matrix is far from singular.
  const Eigen::MatrixXd gram = d.transpose() * d;
  if (Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(gram).eigenvalues()[0] < 1e-6)
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".directions are not linearly independent"));
  return absl::OkStatus();
}

absl::Status Validate(const std::vector<RpsReference>& refs, const RpsSettings& s) {
  if (!(s.part_extent_mm >= 0) || !std::isfinite(s.part_extent_mm))
    return absl::InvalidArgumentError(
        absl::StrCat("rps: part_extent_mm must be finite and >= 0, got ", s.part_extent_mm));
  if (s.max_iterations < 1 || s.max_iterations > 1000)
    return absl::InvalidArgumentError(
        absl::StrCat("rps: max_iterations must be in [1, 1000], got ", s.max_iterations));
  if (refs.empty()) return absl::InvalidArgumentError("rps: references is empty");
  for (std::size_t i = 0; i < refs.size(); ++i) RETURN_IF_ERROR(ValidateReference(refs[i], i));
  return absl::OkStatus();
}

// Refuses a set that leaves a motion free; otherwise the condition of the
// scaled normal matrix on the nominal points (rigid_dofs.h).
absl::StatusOr<double> CheckLocksAll(const std::vector<RpsReference>& refs, const RpsSettings& s) {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& r : refs) centre += r.nominal_mm;
  centre /= static_cast<double>(refs.size());
  double extent = s.part_extent_mm;
  if (extent == 0)
    for (const auto& r : refs) extent = std::max(extent, (r.nominal_mm - centre).norm());
  extent = std::max(extent, 1.0);  // all references at one point: any length will do
  DofMatrix normal = DofMatrix::Zero();
  for (const auto& r : refs)
    for (const auto& d : r.directions) {
      const RigidParams row = ScaledAnalysisRow(r.nominal_mm, d, centre, extent);
      normal += r.weight * row * row.transpose();
    }
  const DofAnalysis analysis = AnalyseDofs(normal);
  if (!analysis.free.empty())
    return absl::InvalidArgumentError(absl::StrCat(
        "rps: the references leave free: ", JoinFree(analysis.free),
        " (each reference locks only its directions; add references that lock these)"));
  return analysis.condition;
}

// Weighted residuals sqrt(w)·d·(T·p − q) and their derivatives with respect
// to x, one row per locked direction.
Eigen::VectorXd Residuals(const std::vector<RpsReference>& refs, const RigidMotion& motion,
                          int equations, Eigen::MatrixXd& jacobian) {
  Eigen::VectorXd r(equations);
  jacobian.resize(equations, kRigidDofs);
  int e = 0;
  for (const auto& ref : refs) {
    const double sw = std::sqrt(ref.weight);
    const Eigen::Vector3d moved = motion.transform() * ref.measured_mm;
    const Eigen::Matrix<double, 3, kRigidDofs> j = motion.Jacobian(ref.measured_mm);
    for (const auto& d : ref.directions) {
      r[e] = sw * d.dot(moved - ref.nominal_mm);
      jacobian.row(e) = sw * d.transpose() * j;
      ++e;
    }
  }
  return r;
}

}  // namespace

absl::StatusOr<RpsResult> SolveRps(const std::vector<RpsReference>& refs, const RpsSettings& s) {
  RETURN_IF_ERROR(Validate(refs, s));
  RpsResult out;
  ASSIGN_OR_RETURN(out.condition, CheckLocksAll(refs, s));
  double weight_sum = 0, farthest_mm = 1;
  for (const auto& r : refs) {
    out.equations += static_cast<int>(r.directions.size());
    weight_sum += r.weight * r.directions.size();
    farthest_mm = std::max(farthest_mm, r.measured_mm.norm());
  }
  // Gauss-Newton: J·dx = −r in the least-squares sense, with the columns
  // scaled to unit length (rotation columns are ~|p| long, translations ~1).
  // A step moves no reference by more than about |dt| + |dr|·|p|; at
  // 1e-12 of the coordinates' size that is at the rounding of the data.
  Eigen::MatrixXd j;
  for (out.iterations = 0; out.iterations < s.max_iterations && !out.converged;) {
    const Eigen::VectorXd r = Residuals(refs, RigidMotion(out.x), out.equations, j);
    const Eigen::Matrix<double, kRigidDofs, 1> scale = j.colwise().norm().transpose();
    const Eigen::VectorXd y =
        (j * scale.cwiseInverse().asDiagonal()).colPivHouseholderQr().solve(-r);
    const RigidParams dx = scale.cwiseInverse().cwiseProduct(y);
    if (!dx.allFinite()) return absl::InternalError("rps: Gauss-Newton step is not finite");
    out.x += dx;
    ++out.iterations;
    const double motion_mm = dx.head<3>().norm() + dx.tail<3>().norm() * farthest_mm;
    out.converged = motion_mm <= 1e-12 * farthest_mm;
  }
  const RigidMotion solved(out.x);
  out.nominal_from_measured = solved.transform();
  double before2 = 0, after2 = 0;
  for (const auto& ref : refs) {
    RpsResidual res;
    const Eigen::Vector3d moved = solved.transform() * ref.measured_mm;
    for (const auto& d : ref.directions) {
      res.before_mm.push_back(d.dot(ref.measured_mm - ref.nominal_mm));
      res.after_mm.push_back(d.dot(moved - ref.nominal_mm));
      before2 += ref.weight * res.before_mm.back() * res.before_mm.back();
      after2 += ref.weight * res.after_mm.back() * res.after_mm.back();
    }
    out.residuals.push_back(std::move(res));
  }
  out.rms_before_mm = std::sqrt(before2 / weight_sum);
  out.rms_after_mm = std::sqrt(after2 / weight_sum);
  return out;
}

}  // namespace surfinspect
