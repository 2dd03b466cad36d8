// Per-viewpoint hand-eye calibration against a gauge (paper §II, eq. (1)):
// the sensor at a taught viewpoint scans a gauge of known CAD shape whose
// world pose was surveyed. The scan is first cleaned by link clustering
// (outliers would bias the fit, paper §III), then ICP fits the gauge mesh to
// it, giving gauge_from_sensor, and
//     world_from_sensor = world_from_gauge · gauge_from_sensor.
// The result says how much to trust it: residual statistics, a 6x6 pose
// covariance from the final normal equations scaled by the residual
// variance, 1-σ figures at the sensor origin, and a degeneracy flag when the
// scan does not pin all six degrees of freedom (e.g. only a plane is seen).
#pragma once

#include <Eigen/Geometry>
#include <atomic>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/distance/mesh_index.h"
#include "core/filter/link_clustering.h"
#include "core/registration/icp.h"

namespace surfinspect {

struct CalibrationSettings {
  bool filter_outliers = true;  // link clustering before ICP (the paper's order)
  LinkClusteringSettings filter;
  // Point-to-plane by default: on the demo gauge it converges in a few
  // iterations and its covariance matches the observed error (tests). The
  // paper's Horn step (IcpStep::kPointToPoint) is selectable; it stops on a
  // flat cost a few µm from the optimum, so its σ is optimistic.
  IcpSettings icp = [] {
    IcpSettings s;
    s.step = IcpStep::kPointToPlane;
    return s;
  }();
  // Coarse search before ICP: the robot's nominal pose can be off by
  // degrees, which at a 400 mm stand-off moves the gauge by tens of mm,
  // beyond ICP's capture range. Rotations about the sensor origin on a grid
  // of +-coarse_search_deg in coarse_step_deg steps (per axis) are scored by
  // the truncated mean squared distance of a small subsample; ICP starts
  // from the best. 0 = off.
  double coarse_search_deg = 6.0;
  double coarse_step_deg = 3.0;
  std::size_t coarse_points = 1500;
  // Smallest / largest eigenvalue of the normal matrix, taken about the
  // points' centroid with rotations scaled by their RMS radius (so the ratio
  // is unit-free). Below this the fit is flagged as degenerate.
  double degeneracy_threshold = 1e-3;
};

struct CalibrationResult {
  Eigen::Isometry3d world_from_sensor = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d gauge_from_sensor = Eigen::Isometry3d::Identity();
  IcpResult icp;
  std::size_t scan_points = 0;      // valid points in the scan
  std::size_t filtered_points = 0;  // removed by link clustering
  double rms_mm = 0;                // point-to-plane residual RMS of the inliers
  // Percentiles of |residual| (linear interpolation, core/types/percentile.h);
  // 0 when there are no residuals.
  double residual_p50_mm = 0, residual_p95_mm = 0, residual_p99_mm = 0;
  double inlier_fraction = 0;  // inliers / points used by ICP
  // Covariance of x = [ω (rad), t (mm)], the left perturbation of
  // gauge_from_sensor in the gauge frame: σ² (JᵀJ)⁻¹.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  double sigma_translation_um = 0;  // 1-σ (RMS over x, y, z) of the sensor origin
  double sigma_rotation_deg = 0;    // 1-σ (RMS over the three axes) of the rotation
  double degeneracy_ratio = 0;      // see CalibrationSettings::degeneracy_threshold
  bool degenerate = false;
  double coarse_rotation_deg = 0;  // rotation the coarse search applied to the guess
  std::vector<std::string> warnings;
};

absl::StatusOr<CalibrationResult> CalibrateViewpoint(
    const MeshIndex& gauge_in_gauge, const Eigen::Isometry3d& world_from_gauge,
    const PointCloud& scan_in_sensor, const Eigen::Isometry3d& initial_world_from_sensor,
    const CalibrationSettings& settings, const std::atomic<bool>* cancel = nullptr);

}  // namespace surfinspect
