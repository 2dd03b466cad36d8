#include "client/agent/verify_cell.h"

#include <cmath>
#include <ctime>
#include <filesystem>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/io/atomic_file.h"
#include "core/registration/calibration.h"
#include "core/types/status_macros.h"

namespace surfinspect::client {
namespace fs = std::filesystem;
namespace {

ViewVerification VerifyView(const CellViewpoint& vp, const MeshIndex& gauge,
                            const GaugeScanFn& scan, const DriftLimits& limits) {
  const auto t0 = std::chrono::steady_clock::now();
  ViewVerification out;
  out.name = vp.name;
  auto cloud = scan(vp);
  if (!cloud.ok()) {
    out.status = cloud.status();
    return out;
  }
  CalibrationSettings s;
  s.coarse_search_deg = 0;  // the pose is expected within µm of the stored one
  auto fit = CalibrateViewpoint(gauge, vp.world_from_gauge, *cloud, *vp.world_from_sensor, s);
  if (!fit.ok()) {
    out.status = fit.status();
  } else if (fit->degenerate || !fit->covariance.allFinite()) {
    out.status =
        absl::FailedPreconditionError("the gauge scan does not pin all six degrees of freedom");
  } else {
    DriftInput in;
    in.calibrated_world_from_sensor = *vp.world_from_sensor;
    in.verified_world_from_sensor = fit->world_from_sensor;
    in.world_from_gauge = vp.world_from_gauge;
    in.calibration_covariance = fit->covariance;
    in.verify_covariance = fit->covariance;
    in.part_point_world = vp.world_from_gauge.translation();
    out.drift = CheckDrift(in, limits);
    out.rms_mm = fit->rms_mm;
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

int StateNumber(const ViewVerification& v) {
  return v.status.ok() ? static_cast<int>(v.drift.verdict) : 2;
}

}  // namespace

absl::StatusOr<VerifyConfig> VerifyConfigOf(const CellConfig& cell) {
  VerifyConfig c;
  const nlohmann::json v = cell.raw.value("verify", nlohmann::json::object());
  if (!v.is_object()) return absl::InvalidArgumentError(cell.path + ": verify: must be an object");
  try {
    c.every_parts = v.value("every_parts", c.every_parts);
    c.every_s = v.value("every_s", c.every_s);
    c.limits.warn_um = v.value("warn_um", c.limits.warn_um);
    c.limits.fail_um = v.value("fail_um", c.limits.fail_um);
    c.limits.warn_deg = v.value("warn_deg", c.limits.warn_deg);
    c.limits.fail_deg = v.value("fail_deg", c.limits.fail_deg);
    c.limits.significance = v.value("significance", c.limits.significance);
  } catch (const nlohmann::json::exception&) {
    return absl::InvalidArgumentError(cell.path + ": verify: numbers expected");
  }
  if (c.every_parts < 0 || !(c.every_s >= 0))
    return absl::InvalidArgumentError(cell.path + ": verify: every_parts and every_s must be >= 0");
  if (auto st = ValidateDriftLimits(c.limits); !st.ok())
    return absl::InvalidArgumentError(absl::StrCat(cell.path, ": ", st.message()));
  return c;
}

absl::StatusOr<CellVerification> VerifyCell(const CellConfig& cell, const MeshIndex& gauge,
                                            const GaugeScanFn& scan, const DriftLimits& limits) {
  RETURN_IF_ERROR(ValidateDriftLimits(limits));
  for (const auto& vp : cell.viewpoints)
    if (!vp.world_from_sensor)
      return absl::FailedPreconditionError(absl::StrCat(
          "viewpoint ", vp.name, " has no stored calibration; run cell-agent calibrate first"));
  CellVerification out;
  int worst = -1;
  for (const auto& vp : cell.viewpoints) {
    out.views.push_back(VerifyView(vp, gauge, scan, limits));
    const ViewVerification& v = out.views.back();
    if (StateNumber(v) > worst) {
      worst = StateNumber(v);
      out.verdict = static_cast<DriftClass>(worst);
      out.reason = absl::StrCat(
          vp.name, ": ",
          v.status.ok() ? v.drift.reason : absl::StrCat("cannot verify: ", v.status.message()));
    }
  }
  return out;
}

nlohmann::json CellVerificationJson(const CellConfig& cell, const CellVerification& v) {
  nlohmann::json views = nlohmann::json::array();
  for (const auto& w : v.views) {
    nlohmann::json j = {{"name", w.name},
                        {"state", w.status.ok() ? DriftClassName(w.drift.verdict) : "fail"},
                        {"seconds", w.seconds}};
    if (!w.status.ok()) {
      j["error"] = std::string(w.status.message());
    } else {
      j.update({{"at_sensor_um", w.drift.at_sensor_um},
                {"at_part_um", w.drift.at_part_um},
                {"rotation_deg", w.drift.rotation_deg},
                {"sigma_at_part_um", w.drift.sigma_at_part_um},
                {"significance_sigma", w.drift.significance},
                {"significant", w.drift.significant},
                {"rms_mm", w.rms_mm},
                {"reason", w.drift.reason}});
    }
    views.push_back(j);
  }
  return {{"schema", "surfinspect.calibration_status/1"},
          {"cell", cell.name},
          {"checked_at_unix_s", static_cast<int64_t>(std::time(nullptr))},
          {"state", DriftClassName(v.verdict)},
          {"inspecting", v.verdict != DriftClass::kFail},
          {"reason", v.reason},
          {"viewpoints", views}};
}

std::string CellVerificationMetrics(const CellConfig& cell, const CellVerification& v) {
  std::string out =
      "# HELP surfinspect_calibration_state Drift check per viewpoint: 0 ok, 1 warn, 2 fail.\n"
      "# TYPE surfinspect_calibration_state gauge\n";
  for (const auto& w : v.views)
    absl::StrAppend(&out, "surfinspect_calibration_state{cell=\"", cell.name, "\",viewpoint=\"",
                    w.name, "\"} ", StateNumber(w), "\n");
  absl::StrAppend(
      &out,
      "# HELP surfinspect_calibration_drift_um Move of the viewpoint since calibration.\n"
      "# TYPE surfinspect_calibration_drift_um gauge\n");
  for (const auto& w : v.views)
    if (w.status.ok())
      absl::StrAppend(
          &out, absl::StrFormat("surfinspect_calibration_drift_um{cell=\"%s\",viewpoint=\"%s\","
                                "at=\"part\"} %.4f\n"
                                "surfinspect_calibration_drift_um{cell=\"%s\",viewpoint=\"%s\","
                                "at=\"sensor\"} %.4f\n",
                                cell.name, w.name, w.drift.at_part_um, cell.name, w.name,
                                w.drift.at_sensor_um));
  absl::StrAppend(&out,
                  "# HELP surfinspect_calibration_drift_sigma Move at the part in combined sigma.\n"
                  "# TYPE surfinspect_calibration_drift_sigma gauge\n");
  for (const auto& w : v.views)
    if (w.status.ok())
      absl::StrAppend(&out, absl::StrFormat("surfinspect_calibration_drift_sigma{cell=\"%s\","
                                            "viewpoint=\"%s\"} %.3f\n",
                                            cell.name, w.name, w.drift.significance));
  return out;
}

absl::Status WriteVerificationStatus(const std::string& dir, const CellConfig& cell,
                                     const CellVerification& v) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec)
    return absl::PermissionDeniedError(absl::StrCat("cannot create ", dir, ": ", ec.message()));
  if (auto st = WriteStringAtomically(dir + "/calibration_status.json",
                                      CellVerificationJson(cell, v).dump(2) + "\n");
      !st.ok())
    return st;
  return WriteStringAtomically(dir + "/calibration_status.prom", CellVerificationMetrics(cell, v));
}

absl::StatusOr<std::string> KeepPreviousCalibration(const CellConfig& cell) {
  bool calibrated = false;
  for (const auto& vp : cell.viewpoints)
    calibrated = calibrated || vp.world_from_sensor.has_value();
  if (!calibrated) return std::string();
  char stamp[32];
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  std::strftime(stamp, sizeof stamp, "%Y%m%dT%H%M%SZ", &tm);
  const fs::path p(cell.path);
  const std::string out =
      (p.parent_path() / absl::StrCat(p.stem().string(), ".calibration-", stamp, ".json")).string();
  RETURN_IF_ERROR(WriteStringAtomically(out, cell.raw.dump(2) + "\n"));
  return out;
}

DriftMonitor::DriftMonitor(VerifyConfig config,
                           std::function<absl::StatusOr<CellVerification>()> verify, Clock clock)
    : config_(config), verify_(std::move(verify)), clock_(std::move(clock)), last_(clock_()) {}

absl::Status DriftMonitor::BeforePart(int parts_done) {
  if (!failed_.empty()) return absl::FailedPreconditionError(failed_);
  const bool by_parts =
      config_.every_parts > 0 && parts_done - parts_at_last_ >= config_.every_parts;
  const bool by_time = config_.every_s > 0 &&
                       std::chrono::duration<double>(clock_() - last_).count() >= config_.every_s;
  if (!by_parts && !by_time) return absl::OkStatus();
  ++checks_;
  parts_at_last_ = parts_done;
  last_ = clock_();
  auto v = verify_();
  if (!v.ok()) {
    failed_ = absl::StrCat("drift check could not run: ", v.status().message());
  } else if (v->verdict == DriftClass::kFail) {
    failed_ = absl::StrCat("calibration drift: ", v->reason);
  }
  if (!failed_.empty()) return absl::FailedPreconditionError(failed_);
  return absl::OkStatus();
}

}  // namespace surfinspect::client
