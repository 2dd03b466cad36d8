// surfinspect errormap: the signed deviation of a scanned cloud from the
// CAD mesh (paper §IV) as a coloured PLY, and optionally CSV, JSON report,
// PNG and PDF report.
#include <spdlog/spdlog.h>
#include <tbb/parallel_invoke.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>

#include "client/cell/cell_config.h"
#include "client/cell/part_outputs.h"
#include "client/cell/part_recorder.h"
#include "client/cli/commands.h"
#include "client/cli/db_args.h"
#include "client/cli/remote_args.h"
#include "core/distance/mesh_index.h"
#include "core/errormap/error_map.h"
#include "core/errormap/error_map_output.h"
#include "core/errormap/error_map_png.h"
#include "core/io/atomic_file.h"
#include "core/io/io_mesh.h"
#include "core/io/io_point_cloud.h"
#include "core/io/io_transform.h"
#include "core/pipeline/plan_evaluation.h"
#include "core/report/html_report.h"
#include "core/report/pdf_report.h"
#include "core/report/qif_results.h"
#include "core/types/transform.h"
#include "proto/convert.h"
#include "proto/packed_cloud.h"

namespace surfinspect::cli {
namespace {

struct ErrorMapArgs {
  std::string cloud, mesh, world_from_part, out, csv, report, png, pdf, plan, html, qif;
  std::string db, part_id, cell_name = "errormap";  // the part in the PDF and the --db record
  std::string frame = "part";
  std::string png_axis = "auto";
  ErrorMapSettings settings;
  RemoteArgs remote;
};

// The part the reports and the record name: --part-id, or the cloud file's stem.
std::string PartIdOf(const ErrorMapArgs& a) {
  return a.part_id.empty() ? std::filesystem::path(a.cloud).stem().string() : a.part_id;
}

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

double Number(const nlohmann::json& j, const char* key) {
  return j.contains(key) && j[key].is_number() ? j[key].get<double>() : NAN;
}

// What either path computed: the per-point result, the report JSON and the
// PNG bytes.
struct ErrorMapRun {
  ErrorMapResult result;
  nlohmann::json report;
  nlohmann::json mesh;  // the report's "mesh" block
  std::string png_bytes;
  std::vector<std::string> failed, defects;  // for the summary
  // Stage times, s, merged into the report's "timing" block.
  double build_seconds = 0, plan_seconds = 0, png_seconds = 0;
  // In-process with --db: the index the distances were found on, kept for
  // the record's triangle summary instead of a second build.
  std::shared_ptr<const MeshIndex> index;
};

// The server computes; PLY/CSV are written here from its deviations, the
// report and PNG are its bytes (so both paths write the same files, timing
// aside).
ErrorMapRun RemoteErrorMap(const ErrorMapArgs& a, const PointCloud& cloud_in_world,
                           const Eigen::Isometry3d& world_from_part, const TriangleMesh& mesh,
                           const InspectionPlan& plan) {
  if (a.settings.split_components) throw CommandFailed("--split-components is in-process only");
  if (!a.png.empty() && a.png_axis != "auto") throw CommandFailed("--png-axis is in-process only");
  v1::ErrorMapRequest req;
  wire::CloudToRequestProto(cloud_in_world, req.mutable_cloud());
  wire::TransformToProto(world_from_part, req.mutable_world_from_part());
  wire::ErrorMapSettingsToProto(a.settings, req.mutable_settings());
  if (!a.plan.empty()) wire::PlanToProto(plan, req.mutable_plan());
  req.set_return_deviations(true);
  req.set_return_png(!a.png.empty());
  const v1::ErrorMapResponse resp = Take(Connect(a.remote)->ErrorMap(req, mesh));
  ErrorMapRun run;
  run.result.deviation_mm = wire::UnpackFloats(resp.deviations());
  if (run.result.deviation_mm.size() != cloud_in_world.size())
    throw CommandFailed("server sent a wrong deviation count");
  run.report = nlohmann::json::parse(resp.report_json(), nullptr, false);
  if (run.report.is_discarded()) throw CommandFailed("server sent a malformed report");
  run.result.tolerance_mm = Number(run.report["tolerance"], "band_mm");
  run.result.color_range_mm = Number(run.report, "color_range_mm");
  run.png_bytes = resp.png();
  run.failed = client::FailedLines(wire::CharacteristicsFromProto(resp.characteristics()));
  run.defects = client::DefectLines(wire::DefectsFromProto(resp.defects()));
  return run;
}

// The report's "mesh" block.
nlohmann::json MeshJson(std::size_t triangles, const MeshTopology& topo, std::size_t degenerate) {
  spdlog::info("mesh: {} boundary edges, {} non-manifold edges, {} degenerate triangles",
               topo.boundary_edges, topo.nonmanifold_edges, degenerate);
  return {{"triangles", triangles},
          {"boundary_edges", topo.boundary_edges},
          {"nonmanifold_edges", topo.nonmanifold_edges},
          {"degenerate_triangles", degenerate}};
}

// In-process, the distances: the index on `mesh`, then the error map.
std::unique_ptr<MeshIndex> LocalDistances(const ErrorMapArgs& a, const PointCloud& cloud_in_world,
                                          const Eigen::Isometry3d& world_from_part,
                                          TriangleMesh mesh, ErrorMapRun& run) {
  MeshIndexSettings build;
  build.build_threads = a.settings.threads;  // 0 = all cores, as for the queries
  build.hint_certificates = CertificatesPayOnce(cloud_in_world.size(), mesh.num_triangles());
  std::unique_ptr<MeshIndex> index = Take(MeshIndex::Build(std::move(mesh), build));
  spdlog::info(
      "mesh index built in {:.3f} s ({} BVH nodes, {} search; {} degenerate triangles; hint "
      "certificates {})",
      index->info().build_seconds, index->info().bvh_nodes, index->info().search_isa,
      index->info().degenerate_triangles,
      build.hint_certificates
          ? fmt::format("for {} triangles in {:.3f} s", index->info().certifiable_triangles,
                        index->info().certificate_seconds)
          : fmt::format("off: fewer than {} points per triangle", kCertificatePointsPerTriangle));
  run.build_seconds = index->info().build_seconds;
  run.mesh = MeshJson(index->mesh().num_triangles(), index->Topology(),
                      index->info().degenerate_triangles);
  run.result = Take(ComputeErrorMap(*index, cloud_in_world, world_from_part, a.settings));
  spdlog::info(
      "distances for {} points in {:.3f} s ({} answered by hint certificates, {} by "
      "the hint alone)",
      run.result.stats.count, run.result.query_seconds, run.result.certified_points,
      run.result.hint_alone_points);
  return index;
}

// In-process, after the distances: the plan's verdicts, the report and the
// PNG. Reads run.result only, so the PLY may be written from it meanwhile.
void LocalPlan(const ErrorMapArgs& a, const PointCloud& cloud_in_world,
               const PointCloud& cloud_in_part, const MeshIndex& index, const InspectionPlan& plan,
               ErrorMapRun& run) {
  auto t0 = std::chrono::steady_clock::now();
  const PlanOutcome outcome =
      Take(EvaluatePlan(run.result, cloud_in_world, index.mesh(), plan, a.settings.threads));
  run.plan_seconds = Seconds(t0);
  run.report = InspectionReportJson(run.result, a.settings, outcome);
  run.failed = client::FailedLines(outcome.characteristics);
  run.defects = client::DefectLines(outcome.defects);
  if (!a.png.empty()) {
    t0 = std::chrono::steady_clock::now();
    ErrorMapPngOptions png;
    png.defects = &outcome.defects.defects;
    png.part_pass = outcome.pass();
    png.view_axis = a.png_axis == "x" ? 0 : a.png_axis == "y" ? 1 : a.png_axis == "z" ? 2 : -1;
    run.png_bytes = Take(EncodePng(
        Take(RenderErrorMap(cloud_in_part, run.result, ComputeBounds(index.mesh()), png))));
    run.png_seconds = Seconds(t0);
  }
}

void PrintSummary(const ErrorMapArgs& a, const ErrorMapRun& run) {
  const nlohmann::json& j = run.report;
  const nlohmann::json& st = j["statistics"];
  const nlohmann::json& pts = j["points"];
  std::printf("points: %zu (valid %zu, matched %zu within %g mm)\n",
              pts.value("count", std::size_t{0}), pts.value("valid", std::size_t{0}),
              pts.value("matched", std::size_t{0}), a.settings.max_distance_mm);
  std::printf("deviation mm: min %.4f  max %.4f  mean %.4f  std %.4f  rms %.4f\n",
              Number(st, "min_mm"), Number(st, "max_mm"), Number(st, "mean_mm"),
              Number(st, "stddev_mm"), Number(st, "rms_mm"));
  std::printf("percentiles mm: p1 %.4f  p5 %.4f  p50 %.4f  p95 %.4f  p99 %.4f\n",
              Number(st, "p1_mm"), Number(st, "p5_mm"), Number(st, "p50_mm"), Number(st, "p95_mm"),
              Number(st, "p99_mm"));
  std::printf("verdict: %s\n", j["tolerance"].value("reason", std::string("?")).c_str());
  if (!a.plan.empty()) {
    std::printf("part: %s (%zu characteristics, %zu defects)\n",
                j.value("verdict", std::string("?")).c_str(), j["characteristics"].size(),
                j["defects"].size());
    for (const std::string& line : run.failed) std::printf("  failed %s\n", line.c_str());
    for (const std::string& line : run.defects) std::printf("  defect %s\n", line.c_str());
  }
  std::printf("wrote %s%s%s%s%s%s%s%s%s%s%s\n", a.out.c_str(), a.csv.empty() ? "" : ", ",
              a.csv.c_str(), a.report.empty() ? "" : ", ", a.report.c_str(),
              a.png.empty() ? "" : ", ", a.png.c_str(), a.pdf.empty() ? "" : ", ", a.pdf.c_str(),
              a.html.empty() ? "" : ", ", a.html.c_str());
}

// report.html: the report with its inputs, the points in the part frame,
// the mesh as the overlay; the part is named after the cloud file.
void WriteHtml(const ErrorMapArgs& a, const ErrorMapRun& run, const PointCloud& cloud_in_part,
               const TriangleMesh& mesh) {
  nlohmann::json report = run.report;
  report["inputs"] = {{"cloud", a.cloud}, {"mesh", a.mesh}, {"world_from_part", a.world_from_part}};
  HtmlReportInput in;
  in.report = &report;
  in.points_in_part = &cloud_in_part;
  in.deviation_mm = &run.result.deviation_mm;
  in.mesh_in_part = &mesh;
  in.context.part_id = PartIdOf(a);
  Check(WriteHtmlReport(a.html, in));
}

// QIF 3.0 Results: the part is the cloud's file stem, the points are the PLY
// (its path relative to the QIF file).
void WriteQif(const ErrorMapArgs& a, const ErrorMapRun& run, std::size_t points) {
  namespace fs = std::filesystem;
  QifContext c;
  c.part_id = PartIdOf(a);
  c.cell = "surfinspect errormap";
  c.part_model = fs::path(a.mesh).filename().string();
  c.points_uri = fs::absolute(a.out).lexically_relative(fs::absolute(a.qif).parent_path()).string();
  c.points_count = points;
  c.points_frame = a.frame;
  c.time_created = QifTimeNow();
  Check(WriteQifResults(a.qif, run.report.dump(), c));
}

// Records the error map as a part (client/cell/part_recorder.h). The
// in-process path has each point's triangle and its index (run.index); the
// remote one is matched again on an index built here from `mesh`.
void RecordErrorMap(ResultsStore& store, const ErrorMapArgs& a, const PointCloud& cloud_in_world,
                    const Eigen::Isometry3d& world_from_part, const TriangleMesh& mesh,
                    const nlohmann::json& plan_json, const ErrorMapRun& run) {
  client::RecordContext context;
  context.cell = a.cell_name;
  context.plan_hash = a.plan.empty() ? "" : client::PlanHash(plan_json);
  context.world_from_part = world_from_part;
  context.max_distance_mm = a.settings.max_distance_mm;
  context.part = run.index ? run.index : Take(MeshIndex::Build(mesh));
  const std::string part_id = PartIdOf(a);
  PartRecord record =
      Take(client::MakePartRecord(context, part_id, run.report.dump(), "report", cloud_in_world,
                                  run.result.deviation_mm, run.result.triangle_id));
  record.files_json =
      nlohmann::json{{"cloud", a.cloud}, {"errormap.ply", a.out}, {"report", a.report}}.dump();
  const bool written = Take(store.Record(record));
  std::printf("%s %s in %s\n", part_id.c_str(), written ? "recorded" : "was already recorded",
              store.Name().c_str());
}

// The error map, in-process or on the server, and the PLY: written as soon
// as the deviations are known, its rows encoded, synced and renamed beside
// the plan's evaluation, which only reads the same result. Returns the
// PLY's write time, s.
double ErrorMapAndPly(const ErrorMapArgs& a, const PointCloud& cloud_in_world,
                      const PointCloud& cloud_in_part, const Eigen::Isometry3d& world_from_part,
                      const TriangleMesh& mesh, const InspectionPlan& plan, ErrorMapRun& run) {
  std::unique_ptr<MeshIndex> index;
  if (a.remote.remote())
    run = RemoteErrorMap(a, cloud_in_world, world_from_part, mesh, plan);
  else
    index = LocalDistances(a, cloud_in_world, world_from_part, mesh, run);
  const PointCloud& written = a.frame == "world" ? cloud_in_world : cloud_in_part;
  absl::Status ply;
  double ply_seconds = 0;
  tbb::task_group writing;
  writing.run([&] {
    const auto start = std::chrono::steady_clock::now();
    try {
      ply = WriteErrorMapPly(a.out, written, run.result, a.frame);
    } catch (const std::bad_alloc&) {
      ply = absl::ResourceExhaustedError("out of memory writing " + a.out);
    }
    ply_seconds = Seconds(start);
  });
  // A plan that fails waits for the writer first: a task group left by an
  // exception cancels its tasks, and a cancelled encoding would leave rows out.
  try {
    if (index) LocalPlan(a, cloud_in_world, cloud_in_part, *index, plan, run);
  } catch (...) {
    writing.wait();
    throw;
  }
  writing.wait();
  Check(ply);
  if (!a.db.empty()) run.index = std::move(index);
  return ply_seconds;
}

// The command's inputs, read and checked before anything is computed.
struct ErrorMapInputs {
  PointCloud cloud_in_world;
  Eigen::Isometry3d world_from_part;
  nlohmann::json plan_json;  // null without --plan
  TriangleMesh mesh;
  InspectionPlan plan;
  bool keeps_cloud = false;  // the part frame's cloud would be a bit-identical copy
  double read_seconds = 0;
};

ErrorMapInputs ReadInputs(const ErrorMapArgs& a) {
  const auto t0 = std::chrono::steady_clock::now();
  // Each reader is serial, so the two files are read at once; their errors
  // are still reported in the order below. The cloud's task also reads the
  // pose and decides whether the part frame needs a copy of the cloud (a
  // pass over every coordinate), while the mesh is still being read.
  absl::StatusOr<PointCloud> cloud_read;
  absl::StatusOr<Eigen::Isometry3d> pose_read = Eigen::Isometry3d::Identity();
  absl::StatusOr<TriangleMesh> mesh_read;
  ErrorMapInputs in;
  tbb::parallel_invoke(
      [&] {
        cloud_read = ReadPointCloud(a.cloud);
        if (!a.world_from_part.empty()) pose_read = ReadTransformJson(a.world_from_part);
        in.keeps_cloud = cloud_read.ok() && pose_read.ok() &&
                         TransformKeepsCloud(*cloud_read, pose_read->inverse());
      },
      [&] { mesh_read = ReadMesh(a.mesh); });
  in.cloud_in_world = Take(std::move(cloud_read));
  in.world_from_part = Take(std::move(pose_read));
  if (!a.plan.empty()) in.plan_json = Take(client::ReadPlanJson(a.plan));
  in.mesh = Take(std::move(mesh_read));
  // A bad plan is refused before anything is computed.
  in.plan = a.plan.empty() ? PlanFromSettings(a.settings)
                           : Take(ParsePlanForMeshFile(in.plan_json, in.mesh, a.mesh, a.settings));
  in.read_seconds = Seconds(t0);
  spdlog::info("read {} points and {} triangles in {:.3f} s", in.cloud_in_world.size(),
               in.mesh.num_triangles(), in.read_seconds);
  return in;
}

void RunErrorMap(const ErrorMapArgs& a) {
  const std::unique_ptr<ResultsStore> store = a.db.empty() ? nullptr : OpenStore(a.db, false);
  const auto t0 = std::chrono::steady_clock::now();
  const ErrorMapInputs in = ReadInputs(a);
  const PointCloud& cloud_in_world = in.cloud_in_world;
  const Eigen::Isometry3d& world_from_part = in.world_from_part;
  const TriangleMesh& mesh = in.mesh;
  // Reported only. In-process, the index build counts them; for the
  // server, they are counted here meanwhile.
  nlohmann::json mesh_json;
  tbb::task_group counting;
  if (a.remote.remote())
    counting.run([&] {
      mesh_json = MeshJson(mesh.num_triangles(), AnalyzeTopology(mesh), mesh.CountDegenerate());
    });
  // Without --world-from-part the two frames are one: the same points,
  // without a copy of the cloud, when the copy would be bit-identical.
  std::optional<PointCloud> moved;
  if (!in.keeps_cloud) moved = TransformCloud(cloud_in_world, world_from_part.inverse());
  const PointCloud& cloud_in_part = moved ? *moved : cloud_in_world;
  ErrorMapRun run;
  const double ply_seconds =
      ErrorMapAndPly(a, cloud_in_world, cloud_in_part, world_from_part, mesh, in.plan, run);
  counting.wait();
  if (!a.remote.remote()) mesh_json = std::move(run.mesh);
  // Files carry part-frame coordinates by default, so they overlay the CAD.
  const PointCloud& written = a.frame == "world" ? cloud_in_world : cloud_in_part;
  const auto t_write = std::chrono::steady_clock::now();
  if (!a.csv.empty()) Check(WriteErrorMapCsv(a.csv, written, run.result));
  if (!a.png.empty()) Check(WriteStringAtomically(a.png, run.png_bytes));
  if (!a.pdf.empty()) {
    PdfReportInput pdf;
    pdf.part_id = PartIdOf(a);
    pdf.report = &run.report;
    pdf.points_in_part = &cloud_in_part;
    pdf.deviation_mm = &run.result.deviation_mm;
    Check(WritePdfReport(a.pdf, pdf));
  }
  if (!a.html.empty()) WriteHtml(a, run, cloud_in_part, mesh);
  if (!a.qif.empty()) WriteQif(a, run, written.size());
  if (!a.report.empty()) {
    // The remote report's timing is the server's; the local one is all ours.
    nlohmann::json& timing = run.report["timing"];
    timing["read_seconds"] = in.read_seconds;
    if (!a.remote.remote()) {
      timing["build_seconds"] = run.build_seconds;
      timing["plan_seconds"] = run.plan_seconds;
      timing["png_seconds"] = run.png_seconds;
    }
    timing["write_seconds"] = ply_seconds + Seconds(t_write);
    timing["total_seconds"] = Seconds(t0);
    run.report["inputs"] = {
        {"cloud", a.cloud}, {"mesh", a.mesh}, {"world_from_part", a.world_from_part}};
    run.report["mesh"] = mesh_json;
    run.report["output_frame"] = a.frame;
    Check(WriteStringAtomically(a.report, run.report.dump(2) + "\n"));
  }
  PrintSummary(a, run);
  if (store) RecordErrorMap(*store, a, cloud_in_world, world_from_part, mesh, in.plan_json, run);
}

}  // namespace

void AddErrorMapCommand(CLI::App& app) {
  auto a = std::make_shared<ErrorMapArgs>();
  auto* cmd = app.add_subcommand(
      "errormap",
      "Signed deviation of a cloud from the CAD mesh (+ above the surface, - below): "
      "coloured PLY, CSV, JSON report, PNG");
  cmd->add_option("--cloud", a->cloud, "measured cloud, world frame (.pcd/.ply)")->required();
  cmd->add_option("--mesh", a->mesh, "CAD mesh, part frame (.stl/.obj/.ply/.off)")->required();
  cmd->add_option("--world-from-part", a->world_from_part, "transform JSON (default identity)");
  cmd->add_option("--out", a->out,
                  "coloured binary PLY; the deviation as float 'scalar_deviation' (CloudCompare) "
                  "and 'quality' (MeshLab)")
      ->required();
  cmd->add_option("--csv", a->csv, "CSV x,y,z,deviation, one row per input point");
  cmd->add_option("--report", a->report, "JSON report");
  cmd->add_option("--png", a->png, "PNG: map, colour bar, histogram, defect ids");
  cmd->add_option("--pdf", a->pdf,
                  "PDF report (A4): header, verdict, map views, colour bar, histogram, "
                  "characteristics and defects");
  cmd->add_option("--html", a->html,
                  "self-contained interactive report (3D view, tables, histogram), part frame");
  cmd->add_option("--qif", a->qif,
                  "QIF 3.0 Results: characteristics, verdicts, the PLY as the measured points "
                  "(docs/integration.md)");
  cmd->add_option("--plan", a->plan,
                  "inspection plan JSON: regions, comparison points, defect detection "
                  "(docs/inspection-plan.md); its default band is +-tolerance");
  cmd->add_option("--tolerance", a->settings.tolerance_mm, "tolerance band +-MM")->default_val(0.1);
  cmd->add_option("--max-distance", a->settings.max_distance_mm,
                  "points farther from the CAD are unmatched (NaN), mm")
      ->default_val(5.0);
  cmd->add_option("--allowed-outside", a->settings.allowed_fraction_outside,
                  "fraction of matched points allowed outside the band for a pass")
      ->default_val(0.0);
  cmd->add_option("--threads", a->settings.threads, "0 = all cores");
  cmd->add_flag("--split-components", a->settings.split_components,
                "also X/Y/Z and normal components (CSV columns, report)");
  cmd->add_option("--frame", a->frame, "coordinates written to PLY/CSV")
      ->check(CLI::IsMember({"part", "world"}))
      ->default_val("part");
  cmd->add_option("--png-axis", a->png_axis, "view axis for merged clouds (auto = CAD's thinnest)")
      ->check(CLI::IsMember({"auto", "x", "y", "z"}))
      ->default_val("auto");
  AddRemoteOptions(cmd, a->remote);
  AddDbOption(cmd, a->db, "also record the result in this results database");
  cmd->add_option("--part-id", a->part_id,
                  "the part's id in the PDF and the --db record (default: the cloud's stem)");
  cmd->add_option("--cell-name", a->cell_name, "with --db: the cell it is recorded under")
      ->default_val("errormap");
  cmd->callback([a] {
    // Bad parameters are refused before any file is read.
    Check(ValidateErrorMapSettings(a->settings));
    // --threads bounds every step, the two files read at once and the
    // rows encoded in parallel included (the index build is given it too:
    // it makes an arena of its own).
    tbb::task_arena arena(a->settings.threads > 0 ? a->settings.threads
                                                  : tbb::task_arena::automatic);
    arena.execute([&] { RunErrorMap(*a); });
  });
}

}  // namespace surfinspect::cli
