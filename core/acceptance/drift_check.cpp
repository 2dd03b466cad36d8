#include "core/acceptance/drift_check.h"

#include <cmath>

#include "absl/strings/str_format.h"

namespace surfinspect {

absl::Status ValidateDriftLimits(const DriftLimits& l) {
  if (!(l.warn_um > 0 && l.warn_um <= l.fail_um && std::isfinite(l.fail_um)) ||
      !(l.warn_deg > 0 && l.warn_deg <= l.fail_deg && std::isfinite(l.fail_deg)) ||
      !(l.significance > 0))
    return absl::InvalidArgumentError(
        "verify: need 0 < warn_um <= fail_um, 0 < warn_deg <= fail_deg, significance > 0");
  return absl::OkStatus();
}

const char* DriftClassName(DriftClass c) {
  switch (c) {
    case DriftClass::kOk:
      return "ok";
    case DriftClass::kWarn:
      return "warn";
    case DriftClass::kFail:
      return "fail";
  }
  return "?";
}

DriftCheck CheckDrift(const DriftInput& in, const DriftLimits& l) {
  DriftCheck d;
  const Eigen::Isometry3d& old_pose = in.calibrated_world_from_sensor;
  const Eigen::Isometry3d& new_pose = in.verified_world_from_sensor;
  d.at_sensor_um = 1000 * (new_pose.translation() - old_pose.translation()).norm();
  const Eigen::Vector3d p_sensor = old_pose.inverse() * in.part_point_world;
  const Eigen::Vector3d move = new_pose * p_sensor - in.part_point_world;
  d.at_part_um = 1000 * move.norm();
  d.rotation_deg =
      Eigen::AngleAxisd(new_pose.linear() * old_pose.linear().transpose()).angle() * 180.0 / M_PI;
  const Eigen::Matrix3d cov = WorldPointCovariance(
      in.world_from_gauge, in.calibration_covariance + in.verify_covariance, in.part_point_world);
  const Eigen::Vector3d dir =
      move.norm() > 0 ? Eigen::Vector3d(move.normalized()) : Eigen::Vector3d::UnitZ();
  d.sigma_at_part_um = 1000 * std::sqrt(std::max(0.0, dir.dot(cov * dir)));
  d.significance = d.sigma_at_part_um > 0 ? d.at_part_um / d.sigma_at_part_um : INFINITY;
  d.significant = d.significance > l.significance;
  const bool beyond_fail = d.at_part_um > l.fail_um || d.rotation_deg > l.fail_deg;
  const bool beyond_warn = d.at_part_um > l.warn_um || d.rotation_deg > l.warn_deg;
  const std::string figures =
      absl::StrFormat("moved %.1f um at the part (%.1f sigma), %.1f um at the sensor, %.4f deg",
                      d.at_part_um, d.significance, d.at_sensor_um, d.rotation_deg);
  if (beyond_fail && d.significant) {
    d.verdict = DriftClass::kFail;
    d.reason = absl::StrFormat("%s: beyond the fail limit (%.1f um, %.4f deg); recalibrate",
                               figures, l.fail_um, l.fail_deg);
  } else if (beyond_fail || (beyond_warn && d.significant)) {
    d.verdict = DriftClass::kWarn;
    d.reason = absl::StrFormat(
        "%s: %s", figures,
        d.significant ? "beyond the warn limit" : "beyond the fail limit but not significant");
  } else {
    d.reason = figures + ": within limits";
  }
  return d;
}

}  // namespace surfinspect
