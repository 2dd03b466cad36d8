// RPS alignment (the reference point system of a drawing): each reference
// is a nominal point q on the part and the same feature measured on the
// scan, p, both in the part frame (mm), and it locks 1-3 directions — a
// surface point its normal, a locating hole the two directions in its
// plane, a slot the one across it. The rigid correction x (rigid_dofs.h)
// minimises the weighted sum of the locked deviations
//     E(x) = Σ_refs w Σ_d (d · (T(x)·p − q))²,
// solved by Gauss-Newton on x with the exact derivatives of T(x) (each step
// a least-squares solve by Householder QR of the column-scaled Jacobian, so
// the normal matrix's squared condition never enters) until a step moves
// no reference by more than 1e-12 of its distance from the origin (about
// the rounding of the coordinates).
//
// A set that does not lock all six degrees of freedom is refused before the
// solve, naming the free motions: the analysis of rigid_dofs.h on the
// nominal points, about their centroid, rotations scaled by the part's
// extent. The nominal points are used so that the verdict is the drawing's,
// whatever the measurement.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/registration/rigid_dofs.h"

namespace surfinspect {

struct RpsReference {
  std::string name;                                       // for messages; may be empty
  Eigen::Vector3d nominal_mm = Eigen::Vector3d::Zero();   // q, part frame
  Eigen::Vector3d measured_mm = Eigen::Vector3d::Zero();  // p, part frame
  std::vector<Eigen::Vector3d> directions;  // 1-3 unit, linearly independent, part frame
  double weight = 1.0;                      // finite, > 0
};

struct RpsSettings {
  // The length that scales rotations in the degeneracy analysis, mm; 0 =
  // the largest distance of a nominal point from their centroid.
  double part_extent_mm = 0;
  int max_iterations = 50;  // Gauss-Newton steps, in [1, 1000]
};

// The deviations of one reference along its directions, in their order, mm:
// d · (p − q) before the correction, d · (T·p − q) after.
struct RpsResidual {
  std::vector<double> before_mm;
  std::vector<double> after_mm;
};

struct RpsResult {
  // T(x): maps measured points onto the nominal (part frame).
  Eigen::Isometry3d nominal_from_measured = Eigen::Isometry3d::Identity();
  RigidParams x = RigidParams::Zero();
  std::vector<RpsResidual> residuals;  // one per reference, in input order
  double rms_before_mm = 0;            // sqrt(Σ w r² / Σ w) over all equations
  double rms_after_mm = 0;
  int equations = 0;       // locked directions over all references
  double condition = 0;    // λmax / λmin of the scaled normal matrix
  int iterations = 0;      // Gauss-Newton steps taken
  bool converged = false;  // the last step was at the rounding of the data (above)
};

// InvalidArgument naming the field for a bad reference (no or more than 3
// directions, a non-unit or dependent direction, a non-finite point, a bad
// weight) or settings, and for a set that leaves a motion free ("the
// references leave free: rotation about z").
absl::StatusOr<RpsResult> SolveRps(const std::vector<RpsReference>& references,
                                   const RpsSettings& settings = {});

}  // namespace surfinspect
