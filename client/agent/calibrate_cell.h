// `cell-agent calibrate` as a library: for every viewpoint of a cell, read
// its gauge scan, ask the service to calibrate it (retrying transient
// failures with backoff) and keep the calibrated world_from_sensor; then
// store the poses and their quality figures in cell.json. The Calibrate
// call and the sleep are injected.
#pragma once

#include <atomic>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "client/agent/retry.h"
#include "client/cell/cell_config.h"
#include "client/remote/remote_client.h"

namespace surfinspect::client {

using CalibrateFn =
    std::function<absl::StatusOr<v1::CalibrateResponse>(const v1::CalibrateRequest&)>;

struct ViewCalibration {
  std::string name;
  absl::Status status;  // OK: `response` holds the pose and its quality
  v1::CalibrateResponse response;
};

struct CalibrateCellOptions {
  std::string gauge_scans;  // folder of <viewpoint>.pcd; empty = gauge_scan in cell.json
  BackoffSettings backoff;
  SleepFn sleep = SleepUnlessStopped;  // backoff waits
  // Called before each backoff wait with the viewpoint, the failure, calls so far, the wait (s).
  std::function<void(const std::string&, const absl::Status&, int, double)> on_retry;
  uint64_t seed = 1;
  // Called as each viewpoint ends (for a table printed as it goes).
  std::function<void(const ViewCalibration&)> on_view;
};

// Calibrates every viewpoint of `cell`; sets world_from_sensor of those that
// succeed. Stops early (the rest fail as CANCELLED) when `stop` is set.
std::vector<ViewCalibration> CalibrateCell(CellConfig& cell, const CalibrateFn& calibrate,
                                           const CalibrateCellOptions& options,
                                           const std::atomic<bool>& stop);

// Writes the calibrated poses and, per successful viewpoint, its quality
// (CalibrationQualityJson) into cell.json (the previous file kept as .bak).
absl::Status StoreCalibrations(const CellConfig& cell, const std::vector<ViewCalibration>& views);

}  // namespace surfinspect::client
