// Calibration drift of one viewpoint: how far its world_from_sensor, fitted
// again on a fresh gauge scan, has moved since calibration, and whether the
// move matters. Figures (µm, deg):
//   at_sensor_um  the move of the sensor origin;
//   at_part_um    the move of a world point seen by the view (the caller
//                 names it, e.g. the view's gauge origin, where parts are
//                 scanned): what a measurement there would be off by;
//   rotation_deg  the angle of the relative rotation.
// Significance: the move at the part against the combined 1-σ of the two
// fits along the move's direction, Σ = J (C_calibration + C_verify) Jᵀ
// (pose_covariance.h); significant beyond `significance` σ (3 by default).
// Class: fail when significant and beyond a fail limit; warn when
// significant and beyond a warn limit, or beyond a fail limit but not
// significant (the fit cannot tell); ok otherwise.
#pragma once

#include <Eigen/Geometry>
#include <string>

#include "absl/status/status.h"
#include "core/acceptance/pose_covariance.h"

namespace surfinspect {

struct DriftLimits {
  double warn_um = 5.0;   // at the part
  double fail_um = 10.0;  // at the part
  double warn_deg = 0.005;
  double fail_deg = 0.01;
  double significance = 3.0;  // in combined σ
};

// The one validator: 0 < warn <= fail for both, significance > 0.
absl::Status ValidateDriftLimits(const DriftLimits& limits);

struct DriftInput {
  Eigen::Isometry3d calibrated_world_from_sensor = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d verified_world_from_sensor = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d world_from_gauge = Eigen::Isometry3d::Identity();
  PoseCovariance calibration_covariance = PoseCovariance::Zero();
  PoseCovariance verify_covariance = PoseCovariance::Zero();
  Eigen::Vector3d part_point_world = Eigen::Vector3d::Zero();
};

enum class DriftClass { kOk, kWarn, kFail };
const char* DriftClassName(DriftClass c);  // "ok", "warn", "fail"

struct DriftCheck {
  double at_sensor_um = 0, at_part_um = 0, rotation_deg = 0;
  double sigma_at_part_um = 0;  // combined 1-σ along the move at the part
  double significance = 0;      // at_part_um / sigma_at_part_um
  bool significant = false;
  DriftClass verdict = DriftClass::kOk;
  std::string reason;  // one sentence, for logs and the status file
};

DriftCheck CheckDrift(const DriftInput& input, const DriftLimits& limits);

}  // namespace surfinspect
