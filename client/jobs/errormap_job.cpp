#include "client/jobs/errormap_job.h"

#include <tbb/parallel_invoke.h>
#include <tbb/task_group.h>

#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/cell/cell_config.h"
#include "client/cell/cell_part.h"
#include "client/cell/part_files.h"
#include "client/cell/part_outputs.h"
#include "client/cell/part_recorder.h"
#include "core/cad/cad_import.h"
#include "core/distance/mesh_index.h"
#include "core/io/io_mesh.h"
#include "core/io/io_point_cloud.h"
#include "core/io/io_transform.h"
#include "core/io/unit_doubt.h"
#include "core/plan/plan_evaluation.h"
#include "core/report/error_map_png.h"
#include "core/types/status_macros.h"
#include "core/types/transform.h"
#include "proto/convert.h"
#include "proto/packed_cloud.h"

namespace surfinspect::client {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// The job's inputs, read and checked before anything is computed.
struct Inputs {
  PointCloud cloud_in_world;
  Eigen::Isometry3d world_from_part = Eigen::Isometry3d::Identity();
  nlohmann::json plan_json;  // null without a plan
  TriangleMesh mesh;
  InspectionPlan plan;
  bool keeps_cloud = false;  // the part frame's cloud would be a bit-identical copy
  double read_seconds = 0;
  std::optional<ReportCad> cad;  // a STEP/IGES mesh's tessellation
  ReportInputUnits units;
};

// What either path computed: the per-point result, the report, the PNG.
struct Run {
  ErrorMapResult result;
  InspectionReport report;
  ReportMesh mesh;
  std::string png;
  std::vector<std::string> failed, defects;
  // Stage times, s, for the report's timing block.
  double build_seconds = 0, plan_seconds = 0, png_seconds = 0;
  // In-process: the index the distances were found on (the record reuses it).
  std::shared_ptr<const MeshIndex> index;
};

void Log(const JobLog& log, const std::string& line) {
  if (log) log(line);
}

// The mesh in millimetres, the units recorded and doubted
// (core/io/unit_doubt.h); the cloud was scaled as it was read.
absl::Status MeshToMillimetres(const ErrorMapJob& job, Inputs& in, const JobLog& warn) {
  if (in.cad && job.mesh_units.stated)
    return absl::InvalidArgumentError(absl::StrCat(
        "--mesh-units: ", job.mesh, " is a STEP/IGES file, which declares its own unit (",
        in.cad->declared_unit, ") and is read in millimetres whatever it is"));
  ScaleToMillimetres(job.mesh_units.unit, &in.mesh);
  const UnitSubject cloud{"cloud " + job.cloud, "--cloud-units", ExtentOf(in.cloud_in_world),
                          job.cloud_units.stated};
  const UnitSubject mesh{"mesh " + job.mesh, "--mesh-units", ExtentOf(in.mesh),
                         job.mesh_units.stated || in.cad.has_value()};
  in.units = ReportInputUnits{LengthUnitName(job.cloud_units.unit),
                              in.cad ? "mm" : LengthUnitName(job.mesh_units.unit),
                              job.cloud_units.stated, mesh.stated, UnitDoubts(cloud, &mesh)};
  for (const std::string& doubt : in.units.doubts) Log(warn, doubt);
  return absl::OkStatus();
}

absl::StatusOr<Inputs> ReadInputs(const ErrorMapJob& job, const JobLog& log, const JobLog& warn) {
  const auto t0 = Clock::now();
  Inputs in;
  // A STEP/IGES part is tessellated (or taken from the cache) first; its
  // groups are read from the cached OBJ.
  std::string mesh_path = job.mesh;
  if (IsCadPath(job.mesh)) {
    ASSIGN_OR_RETURN(const CadMesh cad, ImportCad(job.mesh, job.cad, job.cad_cache));
    Log(log, CadSummary(cad.report, cad.from_cache));
    mesh_path = cad.mesh_path;
    in.cad = ReportCadOf(cad.report);
  }
  // Each reader is serial, so the two files are read at once; their errors
  // are still reported in the order below. The cloud's task also reads the
  // pose and decides whether the part frame needs a copy of the cloud (a
  // pass over every coordinate), while the mesh is still being read.
  absl::StatusOr<PointCloud> cloud_read;
  absl::StatusOr<Eigen::Isometry3d> pose_read = Eigen::Isometry3d::Identity();
  absl::StatusOr<TriangleMesh> mesh_read;
  tbb::parallel_invoke(
      [&] {
        cloud_read = ReadPointCloud(job.cloud);
        if (cloud_read.ok()) ScaleToMillimetres(job.cloud_units.unit, &*cloud_read);
        if (!job.world_from_part.empty()) pose_read = ReadTransformJson(job.world_from_part);
        in.keeps_cloud = cloud_read.ok() && pose_read.ok() &&
                         TransformKeepsCloud(*cloud_read, pose_read->inverse());
      },
      [&] { mesh_read = ReadMesh(mesh_path); });
  ASSIGN_OR_RETURN(in.cloud_in_world, std::move(cloud_read));
  ASSIGN_OR_RETURN(in.world_from_part, std::move(pose_read));
  if (!job.plan.empty()) {
    ASSIGN_OR_RETURN(in.plan_json, ReadPlanJson(job.plan));
  }
  ASSIGN_OR_RETURN(in.mesh, std::move(mesh_read));
  RETURN_IF_ERROR(MeshToMillimetres(job, in, warn));
  // A bad plan is refused before anything is computed. Its boxes are in
  // millimetres; its groups are matched to the file in the file's unit.
  if (job.plan.empty()) {
    in.plan = PlanFromSettings(job.settings);
  } else {
    ASSIGN_OR_RETURN(in.plan, ParsePlanForMeshFile(in.plan_json, in.mesh, mesh_path, job.settings,
                                                   "plan", job.mesh_units.unit));
  }
  in.read_seconds = Seconds(t0);
  Log(log, absl::StrFormat("read %d points and %d triangles in %.3f s", in.cloud_in_world.size(),
                           in.mesh.num_triangles(), in.read_seconds));
  return in;
}

ReportMesh MeshSummary(std::size_t triangles, const MeshTopology& topo, std::size_t degenerate,
                       const JobLog& log) {
  Log(log, absl::StrFormat("mesh: %d boundary edges, %d non-manifold edges, %d degenerate "
                           "triangles",
                           topo.boundary_edges, topo.nonmanifold_edges, degenerate));
  return {triangles, topo.boundary_edges, topo.nonmanifold_edges, degenerate};
}

// The server computes; the PLY and CSV are written here from its
// deviations, the report and PNG are its bytes (so both paths write the
// same files, timing aside).
absl::StatusOr<Run> RemoteErrorMap(const ErrorMapJob& job, RemoteClient& remote, const Inputs& in) {
  if (job.settings.split_components)
    return absl::InvalidArgumentError("--split-components is in-process only");
  if (!job.png.empty() && job.png_axis >= 0)
    return absl::InvalidArgumentError("--png-axis is in-process only");
  v1::ErrorMapRequest req;
  wire::CloudToRequestProto(in.cloud_in_world, req.mutable_cloud());
  wire::TransformToProto(in.world_from_part, req.mutable_world_from_part());
  wire::ErrorMapSettingsToProto(job.settings, req.mutable_settings());
  if (!job.plan.empty()) wire::PlanToProto(in.plan, req.mutable_plan());
  req.set_return_deviations(true);
  req.set_return_png(!job.png.empty());
  ASSIGN_OR_RETURN(const v1::ErrorMapResponse resp, remote.ErrorMap(req, in.mesh));
  Run run;
  run.result.deviation_mm = wire::UnpackFloats(resp.deviations());
  if (run.result.deviation_mm.size() != in.cloud_in_world.size())
    return absl::DataLossError("server sent a wrong deviation count");
  const absl::StatusOr<InspectionReport> report = ParseReport(resp.report_json());
  if (!report.ok()) return absl::DataLossError("server sent a malformed report");
  run.report = *report;
  run.result.tolerance_mm = run.report.tolerance.band_mm;
  run.result.color_range_mm = run.report.color_range_mm;
  run.png = resp.png();
  run.failed = FailedLines(wire::CharacteristicsFromProto(resp.characteristics()));
  run.defects = DefectLines(wire::DefectsFromProto(resp.defects()));
  return run;
}

// In-process, the distances: the index on the mesh, then the error map.
absl::StatusOr<std::unique_ptr<MeshIndex>> LocalDistances(const ErrorMapJob& job, const Inputs& in,
                                                          Run& run, const JobLog& log) {
  MeshIndexSettings build;
  build.build_threads = job.settings.threads;  // 0 = all cores, as for the queries
  build.hint_certificates = CertificatesPayOnce(in.cloud_in_world.size(), in.mesh.num_triangles());
  ASSIGN_OR_RETURN(std::unique_ptr<MeshIndex> index, MeshIndex::Build(in.mesh, build));
  const MeshIndexInfo& info = index->info();
  Log(log, absl::StrCat(
               absl::StrFormat("mesh index built in %.3f s (%d BVH nodes, %s search; %d degenerate "
                               "triangles; hint certificates ",
                               info.build_seconds, info.bvh_nodes, info.search_isa,
                               info.degenerate_triangles),
               build.hint_certificates
                   ? absl::StrFormat("for %d triangles in %.3f s)", info.certifiable_triangles,
                                     info.certificate_seconds)
                   : absl::StrFormat("off: fewer than %g points per triangle)",
                                     kCertificatePointsPerTriangle)));
  run.build_seconds = info.build_seconds;
  run.mesh =
      MeshSummary(index->mesh().num_triangles(), index->Topology(), info.degenerate_triangles, log);
  ASSIGN_OR_RETURN(run.result,
                   ComputeErrorMap(*index, in.cloud_in_world, in.world_from_part, job.settings));
  Log(log, absl::StrFormat("distances for %d points in %.3f s (%d answered by hint certificates, "
                           "%d by the hint alone)",
                           run.result.stats.count, run.result.query_seconds,
                           run.result.certified_points, run.result.hint_alone_points));
  return index;
}

// In-process, after the distances: the plan's verdicts, the report and the
// PNG. Reads run.result only, so the PLY may be written from it meanwhile.
absl::Status LocalPlan(const ErrorMapJob& job, const Inputs& in, const PointCloud& cloud_in_part,
                       const MeshIndex& index, Run& run) {
  auto t0 = Clock::now();
  ASSIGN_OR_RETURN(
      const PlanOutcome outcome,
      EvaluatePlan(run.result, in.cloud_in_world, index.mesh(), in.plan, job.settings.threads));
  run.plan_seconds = Seconds(t0);
  run.report = MakeInspectionReport(run.result, job.settings, outcome);
  run.failed = FailedLines(outcome.characteristics);
  run.defects = DefectLines(outcome.defects);
  if (job.png.empty()) return absl::OkStatus();
  t0 = Clock::now();
  ErrorMapPngOptions png;
  png.defects = &outcome.defects.defects;
  png.part_pass = outcome.pass();
  png.view_axis = job.png_axis;
  ASSIGN_OR_RETURN(const RgbImage image,
                   RenderErrorMap(cloud_in_part, run.result, ComputeBounds(index.mesh()), png));
  ASSIGN_OR_RETURN(run.png, EncodePng(image));
  run.png_seconds = Seconds(t0);
  return absl::OkStatus();
}

// What the catalogue's writers read; `written` is the cloud in the job's frame.
PartFileInputs FilesOf(const ErrorMapJob& job, const std::string& part_id, const Run& run,
                       const PointCloud& written, const PointCloud& cloud_in_part,
                       const TriangleMesh& mesh) {
  PartFileInputs f;
  f.part_id = part_id;
  f.points = &written;
  f.points_frame = job.frame;
  f.points_in_part = &cloud_in_part;
  f.error_map = &run.result;
  f.report = &run.report;
  f.png = run.png;
  f.mesh_in_part = &mesh;
  // QIF 3.0 Results: the part is the cloud's file stem, the points are the
  // PLY (its path relative to the QIF file).
  f.qif.part_id = part_id;
  f.qif.cell = "surfinspect errormap";
  f.qif.part_model = fs::path(job.mesh).filename().string();
  if (!job.qif.empty())
    f.qif.points_uri =
        fs::absolute(job.ply).lexically_relative(fs::absolute(job.qif).parent_path()).string();
  f.qif.points_count = written.size();
  f.qif.points_frame = job.frame;
  f.qif.time_created = QifTimeNow();
  return f;
}

// The error map, in-process or on the server, and the PLY: written as soon
// as the deviations are known, its rows encoded, synced and renamed beside
// the plan's evaluation, which only reads the same result. Returns the
// PLY's write time, s.
absl::StatusOr<double> ErrorMapAndPly(const ErrorMapJob& job, RemoteClient* remote,
                                      const Inputs& in, const PointCloud& cloud_in_part,
                                      const PointCloud& written, Run& run, const JobLog& log) {
  std::unique_ptr<MeshIndex> index;
  if (remote) {
    ASSIGN_OR_RETURN(run, RemoteErrorMap(job, *remote, in));
  } else {
    ASSIGN_OR_RETURN(index, LocalDistances(job, in, run, log));
  }
  absl::Status ply;
  double ply_seconds = 0;
  tbb::task_group writing;
  writing.run([&] {
    const auto start = Clock::now();
    PartFileInputs f;
    f.points = &written;
    f.points_frame = job.frame;
    f.error_map = &run.result;
    try {
      ply = WritePartFile(PartFile::kPly, job.ply, f);
    } catch (const std::bad_alloc&) {
      ply = absl::ResourceExhaustedError("out of memory writing " + job.ply);
    }
    ply_seconds = Seconds(start);
  });
  const absl::Status plan =
      index ? LocalPlan(job, in, cloud_in_part, *index, run) : absl::OkStatus();
  writing.wait();
  RETURN_IF_ERROR(plan);
  RETURN_IF_ERROR(ply);
  run.index = std::move(index);
  return ply_seconds;
}

// Records the error map as a part (client/cell/part_recorder.h). The
// in-process path has each point's triangle and its index; the remote one
// is matched again on an index built here from the mesh.
absl::StatusOr<bool> Record(ResultsStore& store, const ErrorMapJob& job, const Inputs& in,
                            const std::string& part_id, const Run& run) {
  RecordContext context;
  context.cell = job.cell_name;
  context.plan_hash = job.plan.empty() ? "" : PlanHash(in.plan_json);
  context.world_from_part = in.world_from_part;
  context.max_distance_mm = job.settings.max_distance_mm;
  context.part = run.index;
  if (!context.part) {
    ASSIGN_OR_RETURN(context.part, MeshIndex::Build(in.mesh));
  }
  ASSIGN_OR_RETURN(
      PartRecord record,
      MakePartRecord(context, part_id, EncodeReport(run.report).dump(), "report", in.cloud_in_world,
                     run.result.deviation_mm, run.result.triangle_id));
  record.files_json = nlohmann::json{
      {"cloud", job.cloud},
      {EntryOf(PartFile::kPly).file_name, job.ply},
      {EntryOf(PartFile::kReport).name,
       job.report}}.dump();
  return store.Record(record);
}

}  // namespace

absl::StatusOr<ErrorMapJobResult> RunErrorMapJob(const ErrorMapJob& job, RemoteClient* remote,
                                                 ResultsStore* store, const JobLog& log,
                                                 const JobLog& warn) {
  RETURN_IF_ERROR(ValidateErrorMapSettings(job.settings));
  const auto t0 = Clock::now();
  ASSIGN_OR_RETURN(const Inputs in, ReadInputs(job, log, warn));
  // Reported only. In-process, the index build counts them; for the
  // server, they are counted here meanwhile.
  ReportMesh mesh_summary;
  tbb::task_group counting;
  if (remote)
    counting.run([&] {
      mesh_summary = MeshSummary(in.mesh.num_triangles(), AnalyzeTopology(in.mesh),
                                 in.mesh.CountDegenerate(), log);
    });
  // Without a pose the two frames are one: the same points, without a copy
  // of the cloud, when the copy would be bit-identical.
  std::optional<PointCloud> moved;
  if (!in.keeps_cloud) moved = TransformCloud(in.cloud_in_world, in.world_from_part.inverse());
  const PointCloud& cloud_in_part = moved ? *moved : in.cloud_in_world;
  // Files carry part-frame coordinates by default, so they overlay the CAD.
  const PointCloud& written = job.frame == "world" ? in.cloud_in_world : cloud_in_part;
  Run run;
  const absl::StatusOr<double> ply_seconds =
      ErrorMapAndPly(job, remote, in, cloud_in_part, written, run, log);
  counting.wait();
  RETURN_IF_ERROR(ply_seconds.status());
  if (!remote) mesh_summary = run.mesh;
  ErrorMapJobResult out;
  out.part_id = job.part_id.empty() ? fs::path(job.cloud).stem().string() : job.part_id;
  run.report.inputs = ReportInputs{job.cloud, job.mesh, job.world_from_part};
  const auto t_write = Clock::now();
  PartFileInputs files = FilesOf(job, out.part_id, run, written, cloud_in_part, in.mesh);
  for (const auto& [file, path] : {std::pair{PartFile::kCsv, &job.csv},
                                   {PartFile::kPng, &job.png},
                                   {PartFile::kPdf, &job.pdf},
                                   {PartFile::kHtml, &job.html},
                                   {PartFile::kQif, &job.qif}})
    if (!path->empty()) RETURN_IF_ERROR(WritePartFile(file, *path, files));
  // The remote report's timing is the server's; the local one is all ours.
  ReportTiming& timing = run.report.timing;
  timing.read_seconds = in.read_seconds;
  if (!remote) {
    timing.build_seconds = run.build_seconds;
    timing.plan_seconds = run.plan_seconds;
    timing.png_seconds = run.png_seconds;
  }
  timing.write_seconds = *ply_seconds + Seconds(t_write);
  timing.total_seconds = Seconds(t0);
  run.report.mesh = mesh_summary;
  run.report.cad = in.cad;
  run.report.input_units = in.units;
  run.report.output_frame = job.frame;
  if (!job.report.empty()) {
    files.report_text = ReportText(run.report);
    RETURN_IF_ERROR(WritePartFile(PartFile::kReport, job.report, files));
  }
  if (store) {
    ASSIGN_OR_RETURN(out.recorded, Record(*store, job, in, out.part_id, run));
  }
  out.report = std::move(run.report);
  out.failed = std::move(run.failed);
  out.defects = std::move(run.defects);
  return out;
}

}  // namespace surfinspect::client
