// `cell-agent verify` as a library: the drift check of a calibrated cell.
// At every viewpoint the gauge is scanned again (by the robot, or read from
// a folder), its pose fitted again from the stored world_from_sensor
// (core/registration/calibration.h, no coarse search), and the change since
// calibration judged by core/acceptance/drift_check.h. The verify fit's
// covariance stands in for the stored calibration's too (same gauge, sensor
// and fit), so the combined σ is √2 times the verify fit's.
//
// cell.json "verify" (all optional):
//   every_parts   verify before a part when this many were inspected since
//                 the last check (0 = never)
//   every_s       ... or when this many seconds have passed (0 = never)
//   warn_um, fail_um, warn_deg, fail_deg, significance   DriftLimits
//
// The state goes to DIR/calibration_status.json and, for a Prometheus
// textfile collector, DIR/calibration_status.prom, each written atomically.
#pragma once

#include <chrono>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "client/cell/cell_config.h"
#include "core/acceptance/drift_check.h"
#include "core/distance/mesh_index.h"

namespace surfinspect::client {

struct VerifyConfig {
  int every_parts = 0;
  double every_s = 0;
  DriftLimits limits;
};

// cell.json "verify"; InvalidArgument "<cell.json>: verify.<field>: ..." for bad values.
absl::StatusOr<VerifyConfig> VerifyConfigOf(const CellConfig& cell);

// A fresh gauge scan (sensor frame) at viewpoint `vp`.
using GaugeScanFn = std::function<absl::StatusOr<PointCloud>(const CellViewpoint& vp)>;

struct ViewVerification {
  std::string name;
  absl::Status status;  // not OK: the view could not be verified (counts as fail)
  DriftCheck drift;
  double rms_mm = 0;   // of the verify fit
  double seconds = 0;  // scan + fit
};

struct CellVerification {
  std::vector<ViewVerification> views;
  DriftClass verdict = DriftClass::kOk;  // the worst view
  std::string reason;                    // the worst view's, with its name
};

// FailedPrecondition "viewpoint V has no stored calibration; run cell-agent
// calibrate first" when any viewpoint is uncalibrated (nothing is scanned).
absl::StatusOr<CellVerification> VerifyCell(const CellConfig& cell, const MeshIndex& gauge,
                                            const GaugeScanFn& scan, const DriftLimits& limits);

nlohmann::json CellVerificationJson(const CellConfig& cell, const CellVerification& v);
// Prometheus text: surfinspect_calibration_state{cell,viewpoint} (0 ok, 1
// warn, 2 fail), surfinspect_calibration_drift_um{cell,viewpoint,at} and
// surfinspect_calibration_drift_sigma{cell,viewpoint}.
std::string CellVerificationMetrics(const CellConfig& cell, const CellVerification& v);
absl::Status WriteVerificationStatus(const std::string& dir, const CellConfig& cell,
                                     const CellVerification& v);

// Copies cell.json to cell.calibration-<UTC stamp>.json beside it when it
// holds calibrations, so a recalibration keeps the old one; returns the path
// written, or "" when there was nothing to keep.
absl::StatusOr<std::string> KeepPreviousCalibration(const CellConfig& cell);

// Decides when the agent verifies (every N parts, every S seconds) and
// whether it may go on inspecting. `verify` runs a check and records its
// state; once a check fails, every later call refuses with its reason.
class DriftMonitor {
 public:
  using Clock = std::function<std::chrono::steady_clock::time_point()>;
  DriftMonitor(VerifyConfig config, std::function<absl::StatusOr<CellVerification>()> verify,
               Clock clock = std::chrono::steady_clock::now);
  // Called before each part with the number inspected so far: OK to go on,
  // FailedPrecondition with the reason to stop.
  absl::Status BeforePart(int parts_done);
  int checks() const { return checks_; }

 private:
  VerifyConfig config_;
  std::function<absl::StatusOr<CellVerification>()> verify_;
  Clock clock_;
  int parts_at_last_ = 0, checks_ = 0;
  std::chrono::steady_clock::time_point last_;
  std::string failed_;
};

}  // namespace surfinspect::client
