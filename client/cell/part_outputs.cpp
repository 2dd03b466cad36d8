#include "client/cell/part_outputs.h"

#include <filesystem>
#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/errormap/error_map_output.h"
#include "core/io/atomic_file.h"
#include "core/report/html_report.h"
#include "core/report/pdf_report.h"
#include "core/report/qif_results.h"
#include "core/types/transform.h"
#include "proto/convert.h"

namespace surfinspect::client {
namespace {

absl::Status FillFromReport(PartOutputs& o) {
  const nlohmann::json j = nlohmann::json::parse(o.report_json, nullptr, false);
  if (j.is_discarded()) return absl::DataLossError("report is not valid JSON");
  try {
    o.tolerance_mm = j.at("tolerance").at("band_mm").get<double>();
    o.color_range_mm = j.at("color_range_mm").get<double>();
    const auto& st = j.at("statistics");
    o.min_mm = st.value("min_mm", 0.0);
    o.max_mm = st.value("max_mm", 0.0);
  } catch (const nlohmann::json::exception&) {
    // Extremes are only for the summary line; colours need the two above.
    if (!(o.tolerance_mm > 0)) return absl::DataLossError("report lacks tolerance.band_mm");
  }
  return absl::OkStatus();
}

// report.pdf, its maps drawn in the part frame.
absl::Status WritePartPdf(const std::string& path, const PartOutputs& o,
                          const nlohmann::json& report, const PointCloud& in_part) {
  PdfReportInput pdf;
  pdf.part_id = o.part_id;
  pdf.cell = o.cell;
  pdf.report = &report;
  pdf.points_in_part = &in_part;
  pdf.deviation_mm = &o.deviation_mm;
  return WritePdfReport(path, pdf);
}

// report.html: the merged points in the part frame, so they overlay the CAD.
absl::Status WriteReportHtml(const std::string& path, const PartOutputs& o,
                             const nlohmann::json& report, const PointCloud& in_part) {
  HtmlReportInput in;
  in.report = &report;
  in.points_in_part = &in_part;
  in.deviation_mm = &o.deviation_mm;
  in.mesh_in_part = o.mesh_in_part.get();
  in.context = {o.part_id, o.cell, o.viewpoints};
  return WriteHtmlReport(path, in);
}

// report.pdf and report.html, drawn from one parse of the report and one
// copy of the merged points in the part frame.
absl::Status WritePeopleReports(const std::string& dir, const PartOutputs& o) {
  const nlohmann::json report = nlohmann::json::parse(o.report_json, nullptr, false);
  if (report.is_discarded()) return absl::DataLossError("report is not valid JSON");
  const PointCloud in_part = TransformCloud(o.merged_in_world, o.world_from_part.inverse());
  if (auto st = WritePartPdf(dir + "/report.pdf", o, report, in_part); !st.ok()) return st;
  return WriteReportHtml(dir + "/report.html", o, report, in_part);
}

// QIF 3.0 Results beside report.json; the scanned points stay in errormap.ply.
QifContext QifContextOf(const PartOutputs& o) {
  QifContext c;
  c.part_id = o.part_id;
  c.cell = o.cell.empty() ? "cell" : o.cell;
  c.points_uri = "errormap.ply";
  c.points_count = o.merged_in_world.size();
  c.time_created = QifTimeNow();
  return c;
}

// QIF is mapped from a surfinspect.report/2 (its characteristics); a report
// of another schema (from a server that predates it) gets no result.qif.
absl::Status WriteQif(const std::string& path, const PartOutputs& o) {
  auto xml = QifResultsXml(o.report_json, QifContextOf(o));
  if (!xml.ok()) {
    const nlohmann::json j = nlohmann::json::parse(o.report_json, nullptr, false);
    const bool report2 = j.is_object() && j.value("schema", "") == "surfinspect.report/2";
    return report2 ? xml.status() : absl::OkStatus();
  }
  return WriteStringAtomically(path, *xml);
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
  auto png = ErrorMapPngBytes(r.merged.cloud_in_world, world_from_part, r.error_map, part, r.plan);
  if (!png.ok()) return png.status();
  o.png = *std::move(png);
  o.merged_in_world = r.merged.cloud_in_world;
  o.deviation_mm = r.error_map.deviation_mm;
  o.failed = FailedLines(r.plan.characteristics);
  o.defects = DefectLines(r.plan.defects);
  if (auto st = FillFromReport(o); !st.ok()) return st;
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
  if (auto st = FillFromReport(o); !st.ok()) return st;
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

absl::Status WritePartOutputs(const std::string& dir, const PartOutputs& o) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return absl::PermissionDeniedError(absl::StrCat(dir, ": ", ec.message()));
  // The PLY/CSV writers only read deviations, tolerance and colour range.
  ErrorMapResult view;
  view.deviation_mm = o.deviation_mm;
  view.tolerance_mm = o.tolerance_mm;
  view.color_range_mm = o.color_range_mm;
  if (auto st = WriteErrorMapPly(dir + "/errormap.ply", o.merged_in_world, view, "world"); !st.ok())
    return st;
  if (auto st = WriteErrorMapCsv(dir + "/deviations.csv", o.merged_in_world, view); !st.ok())
    return st;
  if (auto st = WriteStringAtomically(dir + "/errormap.png", o.png); !st.ok()) return st;
  if (auto st = WritePeopleReports(dir, o); !st.ok()) return st;
  if (auto st = WriteQif(dir + "/result.qif", o); !st.ok()) return st;
  // The report last: its presence means the part's results are complete.
  return WriteStringAtomically(dir + "/report.json", o.report_json);
}

}  // namespace surfinspect::client
