// surfinspect acceptance: the cell's acceptance test in the style of VDI/VDE
// 2634 Part 2/3 (core/acceptance/cell_acceptance.h). Each artefact scan
// SCANS/<measurement>/<viewpoint>.pcd is filtered and registered with the
// cell's calibration (in-process, or by surfinspectd with --server); the
// fits and figures run here. The filter is link clustering with the
// calibration's settings (LinkClusteringSettings defaults, as for the gauge):
// the inspection settings keep mixed pixels at a sphere's silhouette, which
// biased PS by +15 µm and the centre by 10 µm on the demo's sphere. Each viewpoint's calibration
// covariance is refitted from its gauge scan at the stored pose (the calibration's own σ,
// core/registration/calibration.h), so cross-view SD carries it.
#include <spdlog/spdlog.h>

#include <filesystem>

#include "client/cell/cell_config.h"
#include "client/cli/commands.h"
#include "client/cli/remote_args.h"
#include "core/acceptance/cell_acceptance.h"
#include "core/io/atomic_file.h"
#include "core/io/io_mesh.h"
#include "core/io/io_point_cloud.h"
#include "core/registration/calibration.h"
#include "core/registration/registration.h"
#include "core/types/status_macros.h"
#include "proto/convert.h"
#include "proto/packed_cloud.h"

namespace surfinspect::cli {
namespace {

struct AcceptanceArgs {
  std::string cell, scans, artefacts, report;
  RemoteArgs remote;
};

// The covariance of every calibrated viewpoint, refitted on its gauge scan.
std::map<std::string, ViewCalibrationUncertainty> CalibrationUncertainties(
    const client::CellConfig& cell) {
  auto gauge = Take(MeshIndex::Build(Take(ReadMesh(cell.gauge_mesh))));
  std::map<std::string, ViewCalibrationUncertainty> out;
  for (const auto& vp : cell.viewpoints) {
    if (!vp.world_from_sensor) continue;  // RunAcceptance names it if a measurement needs it
    if (vp.gauge_scan.empty())
      throw CommandFailed(cell.path + ": viewpoint " + vp.name + " has no gauge_scan for its σ");
    CalibrationSettings s;
    s.coarse_search_deg = 0;
    const CalibrationResult fit =
        Take(CalibrateViewpoint(*gauge, vp.world_from_gauge, Take(ReadPointCloud(vp.gauge_scan)),
                                *vp.world_from_sensor, s));
    if (!fit.covariance.allFinite())
      throw CommandFailed("viewpoint " + vp.name + ": its gauge scan is degenerate; recalibrate");
    out[vp.name] = {vp.world_from_gauge, fit.covariance};
  }
  return out;
}

LinkClusteringSettings ArtefactFilter() { return LinkClusteringSettings{}; }

// Filters and registers one scan: in-process, or through surfinspectd.
WorldScanFn ScanSource(const AcceptanceArgs& a, const client::CellConfig& cell,
                       std::shared_ptr<client::RemoteClient> remote) {
  return [&a, &cell, remote](const std::string& name,
                             const std::string& view) -> absl::StatusOr<PointCloud> {
    const auto vp = std::find_if(cell.viewpoints.begin(), cell.viewpoints.end(),
                                 [&](const auto& v) { return v.name == view; });
    if (vp == cell.viewpoints.end() || !vp->world_from_sensor)
      return absl::FailedPreconditionError(name + ": viewpoint " + view +
                                           " is not a calibrated viewpoint of " + cell.path);
    const std::string path = a.scans + "/" + name + "/" + view + ".pcd";
    ASSIGN_OR_RETURN(auto cloud, ReadPointCloud(path));
    if (remote) {
      v1::RegisterRequest req;
      req.set_filter(true);
      wire::FilterSettingsToProto(ArtefactFilter(), req.mutable_filter_settings());
      v1::ViewScan* v = req.add_views();
      v->set_name(view);
      wire::TransformToProto(*vp->world_from_sensor, v->mutable_world_from_sensor());
      wire::CloudToRequestProto(cloud, v->mutable_cloud());
      ASSIGN_OR_RETURN(auto resp, remote->Register(req, nullptr));
      return wire::CloudFromProto(resp.merged(), "merged", wire::Limits{});
    }
    std::vector<ViewScan> views{{view, std::move(cloud), *vp->world_from_sensor}};
    RETURN_IF_ERROR(FilterViews(views, ArtefactFilter()));
    ASSIGN_OR_RETURN(auto merged, RegisterToWorld(views));
    return std::move(merged.cloud_in_world);
  };
}

void PrintFigure(const char* name, const nlohmann::json& f) {
  std::printf("%-4s %9.4f mm  U %.4f mm  MPE %.4f mm  %s  (%s)\n", name, f["value"].get<double>(),
              f["U"].get<double>(), f["mpe"].get<double>(), f["pass"].get<bool>() ? "pass" : "FAIL",
              f["measurement"].get<std::string>().c_str());
}

void Acceptance(const AcceptanceArgs& a) {
  const client::CellConfig cell = Take(client::ReadCellConfig(a.cell));
  const std::string text = Take(ReadFileToString(a.artefacts, std::size_t{16} << 20));
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) throw CommandFailed(a.artefacts + ": not valid JSON");
  const Artefacts artefacts = Take(ArtefactsFromJson(j, a.artefacts));
  std::shared_ptr<client::RemoteClient> remote;
  if (a.remote.remote()) remote = Connect(a.remote);
  const auto views = CalibrationUncertainties(cell);
  const AcceptanceResult r = Take(RunAcceptance(artefacts, views, ScanSource(a, cell, remote)));
  nlohmann::json report = AcceptanceReportJson(r, artefacts);
  report["deviations"].push_back(
      "scans are filtered by link clustering with the calibration's settings, not the cell's "
      "inspection filter, which keeps mixed pixels at sphere silhouettes");
  Check(WriteStringAtomically(a.report, report.dump(2) + "\n"));
  PrintFigure("PF", report["PF_mm"]);
  PrintFigure("PS", report["PS_mm"]);
  PrintFigure("F", report["F_mm"]);
  for (const auto& s : report["SD_mm"])
    std::printf("SD   %9.4f mm  U %.4f mm  MPE %.4f mm  %s  (%s, %s %s)\n",
                s["value"].get<double>(), s["U"].get<double>(), s["mpe"].get<double>(),
                s["pass"].get<bool>() ? "pass" : "FAIL", s["position"].get<std::string>().c_str(),
                s["views"][0].get<std::string>().c_str(), s["views"][1].get<std::string>().c_str());
  std::printf("verdict: %s -> %s\n", r.pass ? "pass" : "fail", a.report.c_str());
  if (!r.pass) throw CommandFailed("the cell does not meet its maximum permissible errors");
}

}  // namespace

void AddAcceptanceCommand(CLI::App& app) {
  auto a = std::make_shared<AcceptanceArgs>();
  auto* cmd = app.add_subcommand(
      "acceptance", "Acceptance test of the cell (VDI/VDE 2634 Part 2/3: PF, PS, SD, F)");
  cmd->add_option("--cell", a->cell, "cell.json (calibrated viewpoints)")->required();
  cmd->add_option("--scans", a->scans, "folder of <measurement>/<viewpoint>.pcd")->required();
  cmd->add_option("--artefacts", a->artefacts, "artefacts.json (calibrated values, MPEs)")
      ->required();
  cmd->add_option("--report", a->report, "report JSON to write")->required();
  AddRemoteOptions(cmd, a->remote);
  cmd->callback([a] { Acceptance(*a); });
}

}  // namespace surfinspect::cli
