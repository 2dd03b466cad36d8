// Point-to-mesh ICP (paper §II, Fig. 3): each iteration pairs every point
// with its closest point on the CAD triangles (MeshIndex, the paper's
// point-to-triangle rule of Fig. 2) and then takes a closed-form step:
// Horn's unit-quaternion absolute orientation (point-to-point, the paper's
// eq. (4)), or optionally a linearised point-to-plane Gauss-Newton step
// (Chen & Medioni 1992), which converges in fewer iterations.
//
// Stopping, whichever comes first:
//  - the paper's relative criterion on the cost Δ_i of eq. (4): with
//    δ = (Δ_i − Δ_{i−1}) / (Δ_{i−1} − Δ_{i−2}) (eq. (5)) read as the
//    geometric rate of the decrease, the cost still to be gained is
//    (Δ_{i−1} − Δ_i)·δ/(1 − δ); stop when that is below
//    `relative_cost_tolerance`·Δ_i (and, when δ is not a usable rate, when the
//    plain relative change is below it), or when a step no longer lowers
//    the cost at all (the noise floor);
//  - an absolute cost threshold (mean squared distance, mm²);
//  - `max_iterations`.
// The loop polls a cancellation flag every iteration (and the closest-point
// queries poll it every chunk), so a server can stop it promptly.
#pragma once

#include <Eigen/Geometry>
#include <atomic>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "core/distance/mesh_index.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

enum class IcpStep { kPointToPoint, kPointToPlane };
enum class RobustKernel { kNone, kHuber, kTukey };
enum class IcpStopReason { kRelativeChange, kAbsoluteCost, kMaxIterations };
const char* ToString(IcpStopReason reason);

// Bounds the work of one ICP run: each iteration is a closest-point pass
// over up to max_points points, and the server runs ICP for remote callers.
constexpr int kMaxIcpIterations = 10000;

struct IcpSettings {
  IcpStep step = IcpStep::kPointToPoint;  // the paper's step
  int max_iterations = 100;               // in [0, kMaxIcpIterations]
  // Pairs farther apart than the gate are rejected. The gate starts at
  // `max_correspondence_mm` (must cover the initial pose error) and then
  // follows 4 x the previous RMS, never below `min_correspondence_mm`.
  double max_correspondence_mm = 50.0;
  double min_correspondence_mm = 2.0;
  double trim_fraction = 0.0;  // also drop this worst fraction of pairs
  RobustKernel kernel = RobustKernel::kNone;
  double kernel_scale_mm = 0.05;          // Huber threshold / Tukey cut-off
  double relative_cost_tolerance = 1e-4;  // remaining gain / cost (eq. (5) extrapolated)
  double absolute_cost_mm2 = 0.0;         // stop when the mean squared distance is below
  std::size_t max_points = 40000;         // random subsample (fixed seed); 0 = all points
  uint64_t seed = 1;
  int threads = 0;  // 0 = all cores; results do not depend on it
};

struct IcpResult {
  Eigen::Isometry3d mesh_from_points = Eigen::Isometry3d::Identity();
  bool converged = false;  // stopped by a cost criterion, not max_iterations
  IcpStopReason stop_reason = IcpStopReason::kMaxIterations;
  int iterations = 0;
  double rms_mm = 0;                 // of the inlier pairs at the final pose
  std::size_t points_used = 0;       // after subsampling
  std::size_t inliers = 0;           // pairs within the final gate
  std::vector<double> cost_history;  // Δ_i: mean squared distance per iteration, mm²
  // Final point-to-plane normal matrix J^T W J over the inliers, for the
  // pose perturbation x = [ω (rad), t (mm)] applied on the left in the mesh
  // frame (exp(x) * mesh_from_points). Used for covariance and degeneracy.
  Eigen::Matrix<double, 6, 6> normal_matrix = Eigen::Matrix<double, 6, 6>::Zero();
  std::vector<double> residuals_mm;  // signed point-to-plane residuals of the inliers
  Eigen::Vector3d inlier_centroid = Eigen::Vector3d::Zero();  // mesh frame, mm
  double inlier_radius_mm = 0;  // RMS distance of the inliers from their centroid
};

// Checks the settings: InvalidArgument naming the bad field. RunIcp, the
// wire conversion, the CLI and the cell file all use it.
absl::Status ValidateIcpSettings(const IcpSettings& settings);

// Fails with InvalidArgument for bad settings or fewer than 6 valid points,
// FailedPrecondition when too few pairs fall inside the gate (initial pose
// too far off), Cancelled when `cancel` is set.
absl::StatusOr<IcpResult> RunIcp(const MeshIndex& mesh, const PointCloud& points,
                                 const Eigen::Isometry3d& initial_mesh_from_points,
                                 const IcpSettings& settings,
                                 const std::atomic<bool>* cancel = nullptr);

}  // namespace surfinspect
