#include "client/cell/part_outputs.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/cell/part_files.h"
#include "core/pipeline/inspection_report.h"
#include "core/report/error_map_png.h"
#include "core/report/qif_results.h"
#include "core/report/report_content.h"
#include "core/types/status_macros.h"
#include "core/types/transform.h"
#include "proto/convert.h"

namespace surfinspect::client {
namespace {

// The figures the outputs read from the report's text.
absl::Status FillFromReport(PartOutputs& o) {
  ASSIGN_OR_RETURN(const InspectionReport report, ParseReport(o.report_json));
  if (!(report.tolerance.band_mm > 0)) return absl::DataLossError("report lacks tolerance.band_mm");
  o.tolerance_mm = report.tolerance.band_mm;
  o.color_range_mm = report.color_range_mm;
  // Extremes are only for the summary line.
  o.min_mm = std::isfinite(report.stats.min_mm) ? report.stats.min_mm : 0.0;
  o.max_mm = std::isfinite(report.stats.max_mm) ? report.stats.max_mm : 0.0;
  o.alignment = AlignmentLines(report.alignment);
  return absl::OkStatus();
}

// QIF 3.0 Results beside report.json; the scanned points stay in errormap.ply.
QifContext QifContextOf(const PartOutputs& o) {
  QifContext c;
  c.part_id = o.part_id;
  c.cell = o.cell.empty() ? "cell" : o.cell;
  c.points_uri = EntryOf(PartFile::kPly).file_name;
  c.points_count = o.merged_in_world.size();
  c.time_created = QifTimeNow();
  return c;
}

}  // namespace

std::vector<std::string> FailedLines(const CharacteristicsResult& characteristics) {
  std::vector<std::string> lines;
  for (const CharacteristicResult& c : characteristics.characteristics)
    if (!c.pass) lines.push_back(absl::StrCat(c.name, ": ", c.reason));
  return lines;
}

std::vector<std::string> DefectLines(const DefectsResult& defects) {
  std::vector<std::string> lines;
  for (const Defect& d : defects.defects)
    lines.push_back(absl::StrFormat(
        "%d %s at (%.1f, %.1f, %.1f) mm: peak %+.3f mm, %.1f mm2, %zu points%s%s", d.id,
        DefectKindName(d.kind), d.centroid_mm.x(), d.centroid_mm.y(), d.centroid_mm.z(), d.peak_mm,
        d.area_mm2, d.points, d.region.empty() ? "" : ", in ", d.region));
  return lines;
}

absl::StatusOr<PartOutputs> OutputsFromLocal(const std::string& part_id, const InspectionResult& r,
                                             const InspectionSettings& settings,
                                             const Eigen::Isometry3d& world_from_part,
                                             const TriangleMesh& part) {
  PartOutputs o;
  o.part_id = part_id;
  o.world_from_part = world_from_part;
  o.verdict = r.plan.pass() ? "pass" : "fail";
  o.report_json = ErrorMapReportText(r.error_map, settings.error_map, r.plan);
  ASSIGN_OR_RETURN(
      o.png, ErrorMapPngBytes(r.merged.cloud_in_world, world_from_part, r.error_map, part, r.plan));
  o.merged_in_world = r.merged.cloud_in_world;
  o.deviation_mm = r.error_map.deviation_mm;
  o.failed = FailedLines(r.plan.characteristics);
  o.defects = DefectLines(r.plan.defects);
  RETURN_IF_ERROR(FillFromReport(o));
  return o;
}

absl::StatusOr<PartOutputs> OutputsFromRemote(const v1::InspectResult& r) {
  PartOutputs o;
  o.part_id = r.part_id();
  // A server without the typed verdict (VERDICT_UNSPECIFIED) still sends the string.
  o.verdict = r.part_verdict() == v1::VERDICT_UNSPECIFIED ? r.verdict()
              : r.part_verdict() == v1::VERDICT_PASS      ? "pass"
                                                          : "fail";
  o.failed = FailedLines(wire::CharacteristicsFromProto(r.characteristics()));
  o.defects = DefectLines(wire::DefectsFromProto(r.defects()));
  o.report_json = r.report_json();
  o.png = r.png();
  auto merged =
      wire::CloudFromBytes(r.merged().xyz(), r.merged().width(), r.merged().height(), "merged");
  if (!merged.ok()) return merged.status();
  o.merged_in_world = *std::move(merged);
  o.deviation_mm = wire::UnpackFloats(r.deviations());
  if (o.deviation_mm.size() != o.merged_in_world.size())
    return absl::DataLossError("server sent a deviation count that does not match the cloud");
  RETURN_IF_ERROR(FillFromReport(o));
  return o;
}

v1::PartHeader MakePartHeader(const std::string& part_id, const Eigen::Isometry3d& world_from_part,
                              const InspectionSettings& settings) {
  v1::PartHeader header;
  header.set_part_id(part_id);
  header.set_idempotency_key(part_id);  // a part is inspected once, whoever asks
  wire::TransformToProto(world_from_part, header.mutable_world_from_part());
  wire::ErrorMapSettingsToProto(settings.error_map, header.mutable_error_map());
  wire::FilterSettingsToProto(settings.filter_settings, header.mutable_filter());
  header.set_skip_filter(!settings.filter);
  header.set_return_deviations(true);
  header.set_return_png(true);
  if (settings.plan) wire::PlanToProto(*settings.plan, header.mutable_plan());
  return header;
}

absl::Status WritePartOutputs(const std::string& dir, const PartOutputs& o,
                              const PartFileSet& files, uint64_t* bytes) {
  ASSIGN_OR_RETURN(InspectionReport report, ParseReport(o.report_json));
  report.cad = o.cad;
  report.input_units = o.input_units;
  // The PLY/CSV writers only read deviations, tolerance and colour range.
  ErrorMapResult view;
  view.deviation_mm = o.deviation_mm;
  view.tolerance_mm = o.tolerance_mm;
  view.color_range_mm = o.color_range_mm;
  // The pictures are drawn in the part frame, so they overlay the CAD.
  const PointCloud in_part = TransformCloud(o.merged_in_world, o.world_from_part.inverse());
  PartFileInputs in;
  in.part_id = o.part_id;
  in.cell = o.cell;
  in.points = &o.merged_in_world;
  in.points_frame = "world";
  in.points_in_part = &in_part;
  in.error_map = &view;
  in.report = &report;
  // Decoding then encoding gives the same text, so the text changes only by
  // "cad" and "input_units".
  in.report_text = o.cad || o.input_units ? ReportText(report) : o.report_json;
  in.png = o.png;
  in.mesh_in_part = o.mesh_in_part.get();
  in.viewpoints = o.viewpoints;
  in.qif = QifContextOf(o);
  return WritePartFiles(dir, files, in, bytes);
}

}  // namespace surfinspect::client
