// The part aligned as the plan asks (PlanAlignment, inspection_plan.h),
// measured on the scan as the cell's calibration places it: the correction
// that maps it onto the CAD.
//
//  * rps: each reference measured on the scan (a hole's or slot's centre by
//    MeasureHoles; a surface point as the median signed distance of the
//    points whose closest CAD point lies within its radius, moved along the
//    CAD normal: only the points near it are queried), then SolveRps
//    (core/registration/rps_fit.h) on the locked directions;
//  * best_fit: RunLockedBestFit (core/registration/locked_best_fit.h) on a
//    fixed stride of the scan's points (of those whose closest CAD
//    triangle lies in the plan's regions, when it names some): the fit
//    has 6 unknowns, and the stride depends on the counts alone, so the
//    result does not depend on the threads.
//
// The caller re-maps the scan with the correction and judges the plan
// there (core/pipeline/inspection.cpp). The paper's default, calibrated,
// measures nothing. A reference not measured, a fit that fails or a
// correction beyond the allowed maximum is reported in the outcome, and the
// part fails with it (ApplyAlignmentVerdict): never a silent frame.
#pragma once

#include <Eigen/Geometry>
#include <atomic>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/distance/mesh_index.h"
#include "core/plan/characteristics.h"
#include "core/plan/edge_samples.h"
#include "core/plan/inspection_plan.h"
#include "core/registration/rigid_dofs.h"

namespace surfinspect {

struct AlignmentReferenceResult {
  std::string name;
  std::string kind;  // "hole" | "slot" | "surface"
  bool measured = false;
  Eigen::Vector3d nominal_mm = Eigen::Vector3d::Zero();          // part frame
  Eigen::Vector3d measured_mm = Eigen::Vector3d::Constant(NAN);  // calibrated frame
  std::vector<Eigen::Vector3d> directions;                       // the ones it locks
  std::vector<double> before_mm, after_mm;                       // deviation along each direction
  std::size_t points = 0;  // surface: points within radius; hole: edge points
  std::string reason;      // why not measured, for people
};

struct AlignmentOutcome {
  AlignmentMode mode = AlignmentMode::kCalibrated;
  bool aligned = false;  // a correction was found (and applied by the caller)
  std::string failure;   // why not, for people; the part fails with it
  std::string note;      // a caution for people (a whole-part best-fit)
  // Maps the scan's part-frame points as calibrated onto the CAD.
  Eigen::Isometry3d correction = Eigen::Isometry3d::Identity();
  RigidParams x = RigidParams::Zero();               // (tx, ty, tz, rx, ry, rz), mm and rad
  std::vector<AlignmentReferenceResult> references;  // rps, plan order
  double rms_before_mm = NAN, rms_after_mm = NAN;    // of the locked deviations / pairs
  int dofs = 0;                                      // degrees of freedom fitted
  LockedDofs locked;
  double correction_mm = 0;   // largest displacement of a reference / used point
  double correction_deg = 0;  // rotation angle
  double max_correction_mm = 0, max_correction_deg = 0;
  bool within_max_correction = true;
  std::size_t points_used = 0, inliers = 0;  // best_fit
  int iterations = 0;
  bool converged = false;
  bool ok() const { return failure.empty() && within_max_correction; }
};

// What an alignment is measured on: the scan as the cell's calibration
// places it, before any error map (the pipeline maps the scan once, in the
// frame the alignment gives).
struct AlignmentInputs {
  const MeshIndex& part;
  const PointCloud& cloud_in_world;    // the merged, filtered scan
  Eigen::Isometry3d world_from_part;   // calibrated
  const std::vector<PlanView>& views;  // for the holes: filtered, part frame as calibrated
  double max_distance_mm = 5.0;        // the error map's: farther points are not matched
  int threads = 0;                     // 0 = all cores; the result does not depend on it
};

// Cancelled when `cancel` is raised; every other problem is an outcome's
// failure. `plan` was validated against the part.
absl::StatusOr<AlignmentOutcome> MeasureAlignment(const AlignmentInputs& in,
                                                  const InspectionPlan& plan,
                                                  const std::atomic<bool>* cancel = nullptr);

// A failed or excessive alignment fails the part, the reason first.
void ApplyAlignmentVerdict(const AlignmentOutcome& alignment, CharacteristicsResult* result);

}  // namespace surfinspect
