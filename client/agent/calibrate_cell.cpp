#include "client/agent/calibrate_cell.h"

#include "client/cell/calibration_quality.h"
#include "core/io/io_point_cloud.h"
#include "core/registration/calibration.h"
#include "proto/convert.h"
#include "proto/packed_cloud.h"

namespace surfinspect::client {
namespace {

ViewCalibration CalibrateView(CellViewpoint& vp, const CalibrateFn& calibrate,
                              const CalibrateCellOptions& options, std::mt19937_64& rng,
                              const std::atomic<bool>& stop) {
  ViewCalibration out;
  out.name = vp.name;
  const std::string scan_path =
      options.gauge_scans.empty() ? vp.gauge_scan : options.gauge_scans + "/" + vp.name + ".pcd";
  auto scan = ReadPointCloud(scan_path);
  if (!scan.ok()) {
    out.status = scan.status();
    return out;
  }
  v1::CalibrateRequest req;
  wire::TransformToProto(vp.world_from_gauge, req.mutable_world_from_gauge());
  wire::TransformToProto(vp.nominal_world_from_sensor, req.mutable_initial_world_from_sensor());
  wire::CloudToRequestProto(*scan, req.mutable_scan());
  wire::IcpSettingsToProto(CalibrationSettings{}.icp, req.mutable_icp());
  absl::StatusOr<v1::CalibrateResponse> resp = absl::CancelledError("stop requested");
  RetryHooks hooks{options.sleep, {}};
  if (options.on_retry)
    hooks.on_retry = [&](const absl::Status& st, int calls, double wait_s) {
      options.on_retry(vp.name, st, calls, wait_s);
    };
  RetryWithBackoff(
      [&] {
        resp = calibrate(req);
        return resp.status();
      },
      IsRetryable, options.backoff, hooks, rng, stop);
  if (!resp.ok()) {
    out.status = resp.status();
    return out;
  }
  auto pose = wire::TransformFromProto(resp->world_from_sensor(), "world_from_sensor");
  if (!pose.ok()) {
    out.status = pose.status();
    return out;
  }
  vp.world_from_sensor = *pose;
  out.response = *std::move(resp);
  return out;
}

}  // namespace

std::vector<ViewCalibration> CalibrateCell(CellConfig& cell, const CalibrateFn& calibrate,
                                           const CalibrateCellOptions& options,
                                           const std::atomic<bool>& stop) {
  std::mt19937_64 rng(options.seed);
  std::vector<ViewCalibration> views;
  for (auto& vp : cell.viewpoints) {
    views.push_back(CalibrateView(vp, calibrate, options, rng, stop));
    if (options.on_view) options.on_view(views.back());
  }
  return views;
}

absl::Status StoreCalibrations(const CellConfig& cell, const std::vector<ViewCalibration>& views) {
  std::vector<std::pair<std::string, nlohmann::json>> quality;
  for (const auto& v : views)
    if (v.status.ok()) quality.emplace_back(v.name, CalibrationQualityJson(v.response.quality()));
  return WriteCellCalibrations(cell, quality);
}

}  // namespace surfinspect::client
