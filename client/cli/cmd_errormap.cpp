// surfinspect errormap: the signed deviation of a scanned cloud from the
// CAD mesh (paper §IV) as a coloured PLY, and optionally the other files of
// a part (client/cell/part_files.h). The work is client/jobs/errormap_job.h;
// this file holds the flags and the printing.
#include <spdlog/spdlog.h>
#include <tbb/task_arena.h>

#include <cstdio>

#include "client/cli/commands.h"
#include "client/cli/db_args.h"
#include "client/cli/remote_args.h"
#include "client/cli/unit_args.h"
#include "client/jobs/errormap_job.h"
#include "core/cad/cad_import.h"

namespace surfinspect::cli {
namespace {

struct ErrorMapArgs {
  client::ErrorMapJob job;
  std::string png_axis = "auto";
  std::string db;
  RemoteArgs remote;
  UnitArgs units;
};

void PrintSummary(const ErrorMapArgs& a, const client::ErrorMapJobResult& r) {
  const client::ErrorMapJob& job = a.job;
  const ErrorMapStats& st = r.report.stats;
  std::printf("points: %zu (valid %zu, matched %zu within %g mm)\n", st.count, st.valid, st.matched,
              job.settings.max_distance_mm);
  std::printf("deviation mm: min %.4f  max %.4f  mean %.4f  std %.4f  rms %.4f\n", st.min_mm,
              st.max_mm, st.mean_mm, st.stddev_mm, st.rms_mm);
  std::printf("percentiles mm: p1 %.4f  p5 %.4f  p50 %.4f  p95 %.4f  p99 %.4f\n", st.p1_mm,
              st.p5_mm, st.p50_mm, st.p95_mm, st.p99_mm);
  std::printf("verdict: %s\n", r.report.tolerance.reason.c_str());
  if (r.report.input_units && !r.report.input_units->doubts.empty())
    std::printf(
        "units: DOUBTED (%zu warning(s) on stderr): the deviations may be off by the "
        "unit's factor; state the units to judge this part\n",
        r.report.input_units->doubts.size());
  if (!job.plan.empty()) {
    std::printf("part: %s (%zu characteristics, %zu defects)\n",
                r.report.verdict.empty() ? "?" : r.report.verdict.c_str(),
                r.report.characteristics.size(), r.report.defects.size());
    for (const std::string& line : r.failed) std::printf("  failed %s\n", line.c_str());
    for (const std::string& line : r.defects) std::printf("  defect %s\n", line.c_str());
  }
  std::string wrote = job.ply;
  for (const std::string* path : {&job.csv, &job.report, &job.png, &job.pdf, &job.html})
    if (!path->empty()) wrote += ", " + *path;
  std::printf("wrote %s\n", wrote.c_str());
}

void RunErrorMap(ErrorMapArgs& a) {
  client::ErrorMapJob& job = a.job;
  job.png_axis = a.png_axis == "x" ? 0 : a.png_axis == "y" ? 1 : a.png_axis == "z" ? 2 : -1;
  // Bad parameters are refused before any file is read.
  Check(ValidateErrorMapSettings(job.settings));
  job.cloud_units = a.units.Cloud();
  // A STEP/IGES part declares its own unit: --units is the cloud's alone.
  job.mesh_units = IsCadPath(job.mesh) && a.units.mesh_units.empty() ? InputUnit{} : a.units.Mesh();
  const std::unique_ptr<ResultsStore> store = a.db.empty() ? nullptr : OpenStore(a.db, false);
  const std::unique_ptr<client::RemoteClient> remote =
      a.remote.remote() ? Connect(a.remote) : nullptr;
  // --threads bounds every step, the two files read at once and the rows
  // encoded in parallel included (the index build is given it too: it makes
  // an arena of its own).
  tbb::task_arena arena(job.settings.threads > 0 ? job.settings.threads
                                                 : tbb::task_arena::automatic);
  absl::StatusOr<client::ErrorMapJobResult> result;
  arena.execute([&] {
    result = client::RunErrorMapJob(
        job, remote.get(), store.get(), [](const std::string& line) { spdlog::info("{}", line); },
        WarnUnitDoubt);
  });
  const client::ErrorMapJobResult r = Take(std::move(result));
  PrintSummary(a, r);
  if (store)
    std::printf("%s %s in %s\n", r.part_id.c_str(),
                r.recorded ? "recorded" : "was already recorded", store->Name().c_str());
}

}  // namespace

void AddErrorMapCommand(CLI::App& app) {
  auto a = std::make_shared<ErrorMapArgs>();
  client::ErrorMapJob& job = a->job;
  auto* cmd = app.add_subcommand(
      "errormap",
      "Signed deviation of a cloud from the CAD mesh (+ above the surface, - below): "
      "coloured PLY, CSV, JSON report, PNG");
  cmd->add_option("--cloud", job.cloud, "measured cloud, world frame (.pcd/.ply)")->required();
  cmd->add_option("--mesh", job.mesh,
                  "CAD, part frame: a mesh (.stl/.obj/.ply/.off) or STEP/IGES (.step/.stp/.iges/"
                  ".igs, tessellated and cached: docs/cad.md)")
      ->required();
  cmd->add_option("--chord-tolerance", job.cad.tessellation.chord_tolerance_mm,
                  "STEP/IGES: largest measured tessellation error, mm")
      ->capture_default_str();
  job.cad_cache = DefaultCadCache();
  cmd->add_option("--cad-cache", job.cad_cache, "STEP/IGES: folder of cached tessellations")
      ->capture_default_str();
  AddUnitOptions(cmd, a->units, /*with_mesh=*/true);
  cmd->add_option("--world-from-part", job.world_from_part,
                  "transform JSON (mm; default identity)");
  cmd->add_option("--out", job.ply,
                  "coloured binary PLY; the deviation as float 'scalar_deviation' (CloudCompare) "
                  "and 'quality' (MeshLab)")
      ->required();
  cmd->add_option("--csv", job.csv, "CSV x,y,z,deviation, one row per input point");
  cmd->add_option("--report", job.report, "JSON report");
  cmd->add_option("--png", job.png, "PNG: map, colour bar, histogram, defect ids");
  cmd->add_option("--pdf", job.pdf,
                  "PDF report (A4): header, verdict, map views, colour bar, histogram, "
                  "characteristics and defects");
  cmd->add_option("--html", job.html,
                  "self-contained interactive report (3D view, tables, histogram), part frame");
  cmd->add_option("--qif", job.qif,
                  "QIF 3.0 Results: characteristics, verdicts, the PLY as the measured points "
                  "(docs/integration.md)");
  cmd->add_option("--plan", job.plan,
                  "inspection plan JSON: regions, comparison points, defect detection "
                  "(docs/inspection-plan.md); its default band is +-tolerance");
  cmd->add_option("--tolerance", job.settings.tolerance_mm, "tolerance band +-MM")
      ->default_val(0.1);
  cmd->add_option("--max-distance", job.settings.max_distance_mm,
                  "points farther from the CAD are unmatched (NaN), mm")
      ->default_val(5.0);
  cmd->add_option("--allowed-outside", job.settings.allowed_fraction_outside,
                  "fraction of matched points allowed outside the band for a pass")
      ->default_val(0.0);
  cmd->add_option("--threads", job.settings.threads, "0 = all cores");
  cmd->add_flag("--split-components", job.settings.split_components,
                "also X/Y/Z and normal components (CSV columns, report)");
  cmd->add_option("--frame", job.frame, "coordinates written to PLY/CSV")
      ->check(CLI::IsMember({"part", "world"}))
      ->default_val("part");
  cmd->add_option("--png-axis", a->png_axis, "view axis for merged clouds (auto = CAD's thinnest)")
      ->check(CLI::IsMember({"auto", "x", "y", "z"}))
      ->default_val("auto");
  AddRemoteOptions(cmd, a->remote);
  AddDbOption(cmd, a->db, "also record the result in this results database");
  cmd->add_option("--part-id", job.part_id,
                  "the part's id in the PDF and the --db record (default: the cloud's stem)");
  cmd->add_option("--cell-name", job.cell_name, "with --db: the cell it is recorded under")
      ->default_val("errormap");
  cmd->callback([a] { RunErrorMap(*a); });
}

}  // namespace surfinspect::cli
