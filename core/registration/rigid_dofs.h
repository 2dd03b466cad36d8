// The six degrees of freedom of a rigid correction, shared by the RPS solve
// (rps_fit.h) and the best-fit with locked degrees of freedom
// (locked_best_fit.h).
//
// A correction is x = (tx, ty, tz, rx, ry, rz), millimetres and radians, in
// the part frame:
//     T(x) = Translation(tx, ty, tz) · Rz(rz) · Ry(ry) · Rx(rx),
// so a component that is exactly 0 leaves its factor exactly the identity
// (cos 0 = 1, sin 0 = 0): a locked component is never a parameter and stays
// exactly 0. The derivatives of T(x)·p are exact at any x (no small-angle
// linearisation), so Gauss-Newton on x converges to machine precision.
//
// Degeneracy: a least-squares fit whose normal matrix is rank-deficient
// leaves some motions free. The analysis below scales the rotation columns
// by a length (the part's extent) so that all columns are in mm and
// comparable, and names the null space in the people's terms of DofName().
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <vector>

namespace surfinspect {

// Indices into RigidParams.
enum Dof : int { kTx = 0, kTy, kTz, kRx, kRy, kRz };
constexpr int kRigidDofs = 6;
using RigidParams = Eigen::Matrix<double, kRigidDofs, 1>;  // mm, mm, mm, rad, rad, rad
using DofMatrix = Eigen::Matrix<double, kRigidDofs, kRigidDofs>;

// "translation along x", ..., "rotation about z"; "unknown" out of range.
const char* DofName(int dof);

// The components of x that stay exactly 0 in a fit.
struct LockedDofs {
  bool tx = false, ty = false, tz = false;  // translations along the part's x, y, z
  bool rx = false, ry = false, rz = false;  // rotations about the part's x, y, z
  bool IsLocked(int dof) const;
  int FreeCount() const;
};

// T(x) and the exact derivatives of T(x)·p with respect to x.
class RigidMotion {
 public:
  explicit RigidMotion(const RigidParams& x);
  const Eigen::Isometry3d& transform() const { return transform_; }
  // ∂(T(x)·p)/∂x, columns in Dof order: mm per mm, then mm per rad.
  Eigen::Matrix<double, 3, kRigidDofs> Jacobian(const Eigen::Vector3d& p) const;

 private:
  Eigen::Isometry3d transform_;
  Eigen::Matrix3d rx_, zy_;  // Rx(rx) and Rz(rz)·Ry(ry)
};

// The x of a rigid transform (inverse of RigidMotion; Euler angles ZYX with
// ry in [-90°, 90°]). For tests and for reading a planted truth.
RigidParams ParamsFromTransform(const Eigen::Isometry3d& t);

// One row of the degeneracy analysis: the derivative at x = 0 of the
// residual d·(T(x)·p − q) (d a unit direction, p in mm) about `centre_mm`,
// with the rotation columns divided by `length_mm`:
//     [d, ((p − centre) × d) / length].
// Taken about the centre so that a motion is named as the rotation or
// translation it is there, and scaled so that the columns compare in mm.
RigidParams ScaledAnalysisRow(const Eigen::Vector3d& p_mm, const Eigen::Vector3d& d,
                              const Eigen::Vector3d& centre_mm, double length_mm);

// Relative eigenvalue (to the largest) below which a motion counts as free.
constexpr double kFreeDofRelativeEigenvalue = 1e-9;

struct DofAnalysis {
  // λmax / λmin of the free block of the scaled normal matrix (infinite
  // when a motion is free; NaN when nothing is free to fit).
  double condition = NAN;
  // One entry per free motion, in DofName() terms: "rotation about z", or
  // "translation along y with rotation about z" for a coupled motion.
  std::vector<std::string> free;
};

// Analyses Σ w·row·rowᵀ over ScaledAnalysisRow rows (`scaled_normal`),
// restricted to the unlocked components: eigenvalues below
// kFreeDofRelativeEigenvalue·λmax (or all, when λmax is 0) span the free
// motions, which are named by a reduced row echelon basis of that null space
// (each basis vector led by one DOF; the DOFs within 0.2 of its largest
// component are named).
DofAnalysis AnalyseDofs(const DofMatrix& scaled_normal, const LockedDofs& locked = {});

// "a, b, c" for the free list of a DofAnalysis.
std::string JoinFree(const std::vector<std::string>& free);

}  // namespace surfinspect
