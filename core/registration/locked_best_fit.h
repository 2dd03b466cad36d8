// Best-fit of a scan to its CAD with locked degrees of freedom: robust
// point-to-plane ICP (Chen & Medioni 1992) whose unknowns are only the
// unlocked components of the correction x (rigid_dofs.h). A locked component
// is not a parameter at all, so it stays exactly 0 and its factor of T(x)
// exactly the identity.
//
// Each iteration pairs every point, moved by T(x), with its closest point on
// the mesh (MeshIndex), keeps the pairs within `max_correspondence_mm` whose
// triangle is in the region (an optional per-triangle mask: the points whose
// closest CAD triangle lies in the region, not the region's closest points
// to every point), and takes one Gauss-Newton step of iteratively reweighted
// least squares on the point-to-plane residuals r = n·(T(x)·p − c):
//     Σ w(r) (r + n·J_free(p)·dx)² → min,
// with the exact derivatives J of T(x)·p. The weights are Tukey's biweight
// or Huber's on r / (k·σ), σ = 1.4826·median|r| (the MAD, floored by
// `min_scale_mm`), so a local shape error (a bump, a bent flange) is treated
// as an outlier instead of being aligned away.
//
// The normal equations are summed in fixed chunks of points and the chunks
// reduced in order, and the closest-point queries do not depend on the
// thread count, so the result is the same bit for bit with any `threads`.
#pragma once

#include <Eigen/Geometry>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "core/distance/mesh_index.h"
#include "core/registration/icp.h"
#include "core/registration/rigid_dofs.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

struct LockedBestFitSettings {
  int max_iterations = 50;  // Gauss-Newton steps, in [1, 1000]
  // Pairs farther apart are not used; must cover the initial misplacement.
  double max_correspondence_mm = 5.0;
  RobustKernel kernel = RobustKernel::kTukey;
  // Kernel cut-off in robust sigmas: 4.685 for Tukey and 1.345 for Huber
  // give 95% efficiency on normal residuals (Holland & Welsch 1977).
  double kernel_sigmas = 4.685;
  double min_scale_mm = 0.005;  // floor of σ, so exact data keep their weights
  // Converged when a step moves no point of the cloud's bounding box by
  // more than this, mm.
  double convergence_mm = 1e-7;
  // The allowed correction: the largest displacement of a used point, mm,
  // and the rotation angle, degrees. Exceeding them is reported, not refused.
  double max_correction_mm = INFINITY;
  double max_correction_deg = INFINITY;
  int threads = 0;  // in [0, kMaxQueryThreads], 0 = all cores; results do not depend on it
};

struct LockedBestFitResult {
  // T(x): maps the measured points onto the CAD (part frame).
  Eigen::Isometry3d nominal_from_measured = Eigen::Isometry3d::Identity();
  RigidParams x = RigidParams::Zero();  // locked components exactly 0
  double rms_before_mm = 0;             // of the pairs' distances at x = 0
  double rms_after_mm = 0;              // of the pairs' distances at the result
  std::vector<double> rms_history_mm;   // per iteration, at the pose it started from
  std::size_t points_used = 0;          // pairs at the result (in the gate and the region)
  std::size_t inliers = 0;              // of them, with a robust weight > 0
  double scale_mm = 0;                  // σ of the last weights
  int iterations = 0;                   // Gauss-Newton steps taken
  bool converged = false;               // the last step was below convergence_mm
  double condition = NAN;     // of the free DOFs at x = 0 (rigid_dofs.h's scaled analysis)
  double correction_mm = 0;   // the largest displacement |T·p − p| of a used point
  double correction_deg = 0;  // the rotation angle of T
  bool exceeds_max_correction = false;
};

// Checks the settings: InvalidArgument naming the bad field.
absl::Status ValidateLockedBestFitSettings(const LockedBestFitSettings& settings);

// `points_in_part`: the scan in the part frame, mm (NaN points are no data
// and skipped); `triangle_mask`: empty (the whole mesh) or one entry per
// mesh triangle, non-zero for the region. InvalidArgument for bad settings,
// a mask of the wrong size, fewer than 6 valid points, fewer than 6 pairs,
// or pairs that leave an unlocked motion free ("the points leave free:
// translation along x"); Cancelled when `cancel` is set.
absl::StatusOr<LockedBestFitResult> RunLockedBestFit(const MeshIndex& mesh,
                                                     const PointCloud& points_in_part,
                                                     const std::vector<uint8_t>& triangle_mask,
                                                     const LockedDofs& locked,
                                                     const LockedBestFitSettings& settings,
                                                     const std::atomic<bool>* cancel = nullptr);

}  // namespace surfinspect
