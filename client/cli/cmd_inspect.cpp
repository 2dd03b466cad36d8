// surfinspect inspect: a whole part from a cell.json and a folder of
// per-viewpoint scans (<viewpoint>.pcd): filter, register, error map, and
// the part's result files; in-process or streamed to surfinspectd.
#include <spdlog/spdlog.h>

#include <filesystem>

#include "client/cell/cell_config.h"
#include "client/cell/cell_part.h"
#include "client/cell/part_outputs.h"
#include "client/cell/part_recorder.h"
#include "client/cell/report_context.h"
#include "client/cli/commands.h"
#include "client/cli/db_args.h"
#include "client/cli/remote_args.h"
#include "client/cli/unit_args.h"
#include "core/io/io_mesh.h"
#include "core/io/io_point_cloud.h"
#include "core/pipeline/inspection.h"
#include "proto/convert.h"

namespace surfinspect::cli {
namespace {

struct InspectArgs {
  std::string cell, scans, out, part_id, plan, db;
  std::vector<std::string> outputs;  // catalogue names; empty: the cell's "outputs"
  double tolerance = 0;
  RemoteArgs remote;
};

// "scans/part-001/" and "scans/part-001" both name part-001 (shell
// completion writes the slash).
std::string FolderName(const std::string& path) {
  std::filesystem::path p = std::filesystem::path(path).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();
  return p.filename() == "." || p.filename() == ".." ? "" : p.filename().string();
}

// Records the part from the files just written (client/cell/part_recorder.h).
void Record(ResultsStore& store, const InspectArgs& a, const client::CellConfig& cell,
            const TriangleMesh& part, const std::string& part_id) {
  client::RecordContext context =
      client::RecordContextOf(cell, std::shared_ptr<const MeshIndex>(Take(MeshIndex::Build(part))));
  if (!a.plan.empty()) context.plan_hash = client::PlanHash(Take(client::ReadPlanJson(a.plan)));
  const bool written = Take(client::RecordPartFromFiles(store, context, part_id, a.out));
  std::printf("%s %s in %s\n", part_id.c_str(), written ? "recorded" : "was already recorded",
              store.Name().c_str());
}

void Inspect(const InspectArgs& a) {
  client::CellConfig cell = Take(client::ReadCellConfig(a.cell));
  std::string cad_log;
  Check(client::LoadCellPart(&cell, &cad_log));
  if (!cad_log.empty()) std::fprintf(stderr, "%s\n", cad_log.c_str());
  const client::PartFileSet files =
      a.outputs.empty() ? cell.outputs : Take(client::ParsePartFileSet(a.outputs, "--outputs"));
  const std::unique_ptr<ResultsStore> store = a.db.empty() ? nullptr : OpenStore(a.db, false);
  const auto part_ptr = std::make_shared<const TriangleMesh>(Take(client::ReadCellPartMesh(cell)));
  const TriangleMesh& part = *part_ptr;
  InspectionSettings settings = client::InspectionSettingsOf(cell);
  if (a.tolerance != 0) settings.error_map.tolerance_mm = a.tolerance;
  Check(ValidateErrorMapSettings(settings.error_map));
  if (!a.plan.empty()) {
    client::CellConfig with = cell;
    with.plan = Take(client::ReadPlanJson(a.plan));
    with.plan_source = a.plan;
    settings.plan = Take(client::PlanOf(with, part, settings.error_map));
  } else {
    settings.plan = Take(client::PlanOf(cell, part, settings.error_map));
  }
  std::vector<ViewScan> views;
  std::vector<std::string> doubts;
  for (const auto& vp : cell.viewpoints) {
    const std::string path = a.scans + "/" + vp.name + ".pcd";
    if (!std::filesystem::exists(path)) continue;
    if (!vp.world_from_sensor)
      throw CommandFailed(a.cell + ": viewpoint " + vp.name +
                          " is not calibrated (run cell-agent calibrate)");
    views.push_back(
        {vp.name, Take(client::ReadCellScan(cell, path, &part, &doubts)), *vp.world_from_sensor});
  }
  for (const std::string& d : doubts) WarnUnitDoubt(d);
  if (views.empty()) throw CommandFailed(a.scans + ": no <viewpoint>.pcd scans for this cell");
  const std::string part_id = a.part_id.empty() ? FolderName(a.scans) : a.part_id;
  if (part_id.empty())
    throw CommandFailed(a.scans +
                        ": no folder name to take the part id from; "
                        "give --part-id");
  client::PartOutputs outputs;
  if (a.remote.remote()) {
    const v1::PartHeader header = client::MakePartHeader(part_id, cell.world_from_part, settings);
    auto result = Take(Connect(a.remote)->Inspect(header, part, views, [](const v1::Progress& p) {
      spdlog::info("{} {} ({} points)", v1::Progress::Stage_Name(p.stage()), p.view(), p.points());
    }));
    outputs = Take(client::OutputsFromRemote(result));
  } else {
    auto index = Take(MeshIndex::Build(part));
    const InspectionResult r =
        Take(InspectPart(*index, cell.world_from_part, std::move(views), settings));
    outputs = Take(client::OutputsFromLocal(part_id, r, settings, cell.world_from_part, part));
  }
  outputs.cell = cell.name;
  outputs.world_from_part = cell.world_from_part;
  outputs.mesh_in_part = part_ptr;
  outputs.viewpoints = client::ViewpointCalibrations(cell);
  if (cell.part_cad) outputs.cad = ReportCadOf(*cell.part_cad);
  outputs.input_units = client::CellInputUnits(cell, doubts);
  Check(client::WritePartOutputs(a.out, outputs, files));
  std::printf("%s: %s  (min %.3f mm, max %.3f mm)  -> %s\n", part_id.c_str(),
              outputs.verdict.c_str(), outputs.min_mm, outputs.max_mm, a.out.c_str());
  for (const std::string& line : outputs.alignment) std::printf("  alignment %s\n", line.c_str());
  for (const std::string& line : outputs.failed) std::printf("  failed %s\n", line.c_str());
  for (const std::string& line : outputs.defects) std::printf("  defect %s\n", line.c_str());
  if (store) Record(*store, a, cell, part, part_id);
}

}  // namespace

void AddInspectCommand(CLI::App& app) {
  auto a = std::make_shared<InspectArgs>();
  auto* cmd = app.add_subcommand("inspect", "Inspect a whole part: filter, register, error map");
  cmd->add_option("--cell", a->cell, "cell.json (calibrated viewpoints, part mesh and pose)")
      ->required();
  cmd->add_option("--scans", a->scans, "folder with <viewpoint>.pcd scans of one part")->required();
  cmd->add_option("--out", a->out, "results folder; its files:\n" + client::PartFilesHelp())
      ->required();
  cmd->add_option("--outputs", a->outputs,
                  "the files to write besides report.json, by name (" + client::PartFileNames() +
                      "); default: the cell's \"outputs\", else all but csv")
      ->delimiter(',');
  cmd->add_option("--part-id", a->part_id, "default: the scans folder's name");
  cmd->add_option("--tolerance", a->tolerance, "override the cell's tolerance, mm (0 = keep)");
  cmd->add_option("--plan", a->plan,
                  "inspection plan JSON (docs/inspection-plan.md); default: the cell's plan");
  AddRemoteOptions(cmd, a->remote);
  AddDbOption(cmd, a->db, "also record the part in this results database");
  cmd->callback([a] { Inspect(*a); });
}

}  // namespace surfinspect::cli
