// surfinspect calibrate: one viewpoint's gauge calibration (paper §II, eq.
// (1)), in-process or on a server. Both paths produce the same
// CalibrateResponse and so write the same bytes.
#include <spdlog/spdlog.h>

#include "client/cell/calibration_quality.h"
#include "client/cli/commands.h"
#include "client/cli/remote_args.h"
#include "core/io/atomic_file.h"
#include "core/io/io_mesh.h"
#include "core/io/io_point_cloud.h"
#include "core/io/io_transform.h"
#include "core/registration/calibration.h"
#include "proto/convert.h"
#include "proto/packed_cloud.h"

namespace surfinspect::cli {
namespace {

struct CalibrateArgs {
  std::string gauge, world_from_gauge, scan, initial, out, report;
  bool point_to_point = false, point_to_plane = false, no_filter = false;
  int max_iterations = 100;
  RemoteArgs remote;
};

// The one-line summary printed after a calibration.
std::string CalibrationLine(const std::string& name, const v1::CalibrateResponse& r) {
  const v1::CalibrationQuality& q = r.quality();
  char buf[256];
  std::snprintf(buf, sizeof(buf), "%-8s rms %.4f mm  sigma %.2f um / %.5f deg  %s%s", name.c_str(),
                q.rms_mm(), q.sigma_translation_um(), q.sigma_rotation_deg(),
                q.converged() ? "converged" : "NOT converged",
                q.degenerate() ? "  DEGENERATE" : "");
  return buf;
}

}  // namespace

void Calibrate(const CalibrateArgs& a) {
  if (a.point_to_point && a.point_to_plane)
    throw CommandFailed("--point-to-point and --point-to-plane exclude each other");
  CalibrationSettings settings;
  if (a.point_to_point) settings.icp.step = IcpStep::kPointToPoint;
  settings.icp.max_iterations = a.max_iterations;
  settings.filter_outliers = !a.no_filter;
  // Bad parameters are refused before any file is read.
  Check(ValidateIcpSettings(settings.icp));
  const TriangleMesh gauge = Take(ReadMesh(a.gauge));
  v1::CalibrateRequest req;
  wire::TransformToProto(Take(ReadTransformJson(a.world_from_gauge)),
                         req.mutable_world_from_gauge());
  wire::TransformToProto(Take(ReadTransformJson(a.initial)),
                         req.mutable_initial_world_from_sensor());
  wire::CloudToRequestProto(Take(ReadPointCloud(a.scan)), req.mutable_scan());
  wire::IcpSettingsToProto(settings.icp, req.mutable_icp());
  wire::FilterSettingsToProto(settings.filter, req.mutable_filter());
  req.set_skip_filter(a.no_filter);

  v1::CalibrateResponse resp;
  if (a.remote.remote()) {
    resp = Take(Connect(a.remote)->Calibrate(req, gauge));
  } else {
    // The same conversions the server applies, so both paths agree.
    const wire::Limits limits;
    auto index = Take(MeshIndex::Build(gauge));
    const CalibrationResult r = Take(CalibrateViewpoint(
        *index, Take(wire::TransformFromProto(req.world_from_gauge(), "world_from_gauge")),
        Take(wire::CloudFromProto(req.scan(), "scan", limits)),
        Take(
            wire::TransformFromProto(req.initial_world_from_sensor(), "initial_world_from_sensor")),
        settings));
    wire::CalibrationToProto(r, &resp);
  }
  const Eigen::Isometry3d world_from_sensor =
      Take(wire::TransformFromProto(resp.world_from_sensor(), "world_from_sensor"));
  Check(WriteTransformJson(a.out, world_from_sensor));
  if (!a.report.empty())
    Check(WriteStringAtomically(a.report,
                                client::CalibrationQualityJson(resp.quality()).dump(2) + "\n"));
  std::printf("%s\n", CalibrationLine("viewpoint", resp).c_str());
  for (const auto& w : resp.quality().warnings()) spdlog::warn("{}", w);
}

void AddCalibrateCommand(CLI::App& app) {
  auto a = std::make_shared<CalibrateArgs>();
  auto* cmd = app.add_subcommand(
      "calibrate", "Fit the gauge mesh to a gauge scan (filter + ICP) and write world_from_sensor");
  cmd->add_option("--gauge", a->gauge, "gauge mesh (gauge frame, mm)")->required();
  cmd->add_option("--world-from-gauge", a->world_from_gauge, "surveyed gauge pose (JSON)")
      ->required();
  cmd->add_option("--scan", a->scan, "gauge scan (sensor frame)")->required();
  cmd->add_option("--initial-world-from-sensor", a->initial, "robot's nominal pose (JSON)")
      ->required();
  cmd->add_option("--out", a->out, "calibrated world_from_sensor (JSON)")->required();
  cmd->add_option("--report", a->report, "quality report (JSON)");
  cmd->add_flag("--point-to-plane", a->point_to_plane, "point-to-plane steps (the default)");
  cmd->add_flag("--point-to-point", a->point_to_point, "Horn's point-to-point steps (the paper's)");
  cmd->add_flag("--no-filter", a->no_filter, "skip the link-clustering filter");
  cmd->add_option("--max-iterations", a->max_iterations, "ICP iteration cap");
  AddRemoteOptions(cmd, a->remote);
  cmd->callback([a] { Calibrate(*a); });
}

}  // namespace surfinspect::cli
