#include "core/report/html_report.h"

#include <chrono>
#include <cmath>

#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "core/io/atomic_file.h"
#include "core/report/html_escape.h"
#include "core/report/html_histogram.h"
#include "core/report/html_section_plot.h"
#include "core/report/viewer_assets.h"
#include "core/report/viewer_page.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

using nlohmann::json;

// What the viewer reads: scale, palette, the payload's layout, defects.
// The CAD triangles the scan did not wholly see (report.coverage), for the
// view to grey out on the embedded mesh; null without coverage, without a
// mesh, or when the listed ids do not fit the mesh (another CAD).
json UnseenJson(const InspectionReport& report, const HtmlPayload& p) {
  const std::size_t triangles = p.mesh_triangles.size() / 3;
  if (!report.coverage || triangles == 0) return nullptr;
  const ReportCoverage& c = *report.coverage;
  if (!c.triangles.empty() && c.triangles.back() >= triangles) return nullptr;
  return {{"distance_mm", c.distance_mm},
          {"surface", c.surface},
          {"triangles", c.triangles},
          {"covered", c.covered}};
}

json ViewerData(const InspectionReport& report, const HtmlReportContext& ctx,
                const DeviationPalette& palette, const HtmlPayload& p, std::string& blob) {
  json data = {{"kind", "report"},
               {"part_id", ctx.part_id},
               {"cell", ctx.cell},
               {"tolerance_mm", palette.tolerance_mm},
               {"range_mm", palette.range_mm},
               {"palette", PaletteJson(palette)},
               {"three", std::string(GetViewerAssets().three_version)}};
  data["points"] = {{"input", p.input_points},
                    {"finite", p.finite_points},
                    {"shown", p.positions.size()},
                    {"thinned", p.thinned},
                    {"cell_mm", p.cell_mm},
                    {"per_cell", p.per_cell},
                    {"min", Vec3Json(p.positions.min)},
                    {"step", Vec3Json(p.positions.step)},
                    {"deviation_step_mm", p.deviation_step_mm},
                    {"positions", AppendToPayload(blob, p.positions.xyz)},
                    {"deviations", AppendToPayload(blob, p.deviation)},
                    {"palette_index", AppendToPayload(blob, p.palette_index)}};
  data["mesh"] = nullptr;
  data["mesh_omitted"] = p.mesh_omitted;
  if (!p.mesh_triangles.empty()) data["mesh"] = MeshJson(p.mesh_vertices, p.mesh_triangles, blob);
  data["unseen"] = UnseenJson(report, p);
  data["defects"] = json::array();
  for (const ReportDefect& d : report.defects)
    data["defects"].push_back(
        {{"id", d.id},
         {"kind", d.kind},
         {"centroid_mm", {d.centroid_mm.x(), d.centroid_mm.y(), d.centroid_mm.z()}},
         {"extent_mm", d.extent_mm},
         {"peak_mm", d.peak_mm},
         {"region", d.region}});
  return data;
}

std::string Title(const HtmlReportContext& ctx, const InspectionReport& report) {
  const std::string verdict = report.verdict.empty() ? "?" : report.verdict;
  return absl::StrCat("surfinspect report: ", ctx.part_id, " (", verdict, ")");
}

std::string SidePane(const InspectionReport& report, const HtmlReportContext& ctx,
                     const DeviationPalette& palette) {
  const std::string sections = SectionPlotsHtml(report, palette);
  return absl::StrCat("<aside id=\"side\">\n<h2>Characteristics</h2>\n",
                      CharacteristicsTable(report), "<h2>Defects</h2>\n", DefectsTable(report),
                      AlignmentSection(report), sections.empty() ? "" : "<h2>Sections</h2>\n",
                      sections, "<h2>Histogram</h2>\n", HistogramSvg(report.histogram, palette),
                      "<h2>Statistics (all points)</h2>\n", StatisticsTable(report),
                      "<h2>Calibration</h2>\n", CalibrationTable(ctx), "<h2>Settings</h2>\n",
                      SettingsTable(report), "</aside>\n");
}

absl::Status CheckInput(const HtmlReportInput& in) {
  if (!in.report) return absl::InvalidArgumentError("HTML report: no report object");
  if (!in.points_in_part || !in.deviation_mm)
    return absl::InvalidArgumentError("HTML report: no points or deviations");
  if (!(in.report->tolerance.band_mm > 0))
    return absl::InvalidArgumentError("HTML report: report lacks tolerance.band_mm");
  if (!std::isfinite(in.report->color_range_mm))
    return absl::InvalidArgumentError("HTML report: report lacks color_range_mm");
  return absl::OkStatus();
}

absl::StatusOr<HtmlReportPage> BuildPage(const HtmlReportInput& in) {
  const InspectionReport& report = *in.report;
  const auto t0 = std::chrono::steady_clock::now();
  const DeviationPalette palette =
      MakeDeviationPalette(report.tolerance.band_mm, report.color_range_mm);
  auto payload =
      BuildHtmlPayload(*in.points_in_part, *in.deviation_mm, palette, in.mesh_in_part, in.payload);
  if (!payload.ok()) return payload.status();
  std::string blob;
  const json data = ViewerData(report, in.context, palette, *payload, blob);
  HtmlReportPage page;
  page.shown_points = payload->positions.size();
  const std::string payload_text = absl::Base64Escape(blob);
  page.payload_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  page.html = absl::StrCat(
      ViewerHead(Title(in.context, report)), VerdictBanner(report, in.context), "<main>\n",
      ViewerPane(absl::StrCat(
          "<label><input type=\"checkbox\" id=\"mesh-toggle\" checked> CAD mesh</label>"
          "<label><input type=\"checkbox\" id=\"defect-toggle\" checked> defects</label>",
          data["unseen"].is_null()
              ? ""
              : "<label><input type=\"checkbox\" id=\"unseen-toggle\" checked> not seen</label>")),
      SidePane(report, in.context, palette), "</main>\n<footer>surfinspect report, three.js ",
      GetViewerAssets().three_version, "</footer>\n", ViewerScripts(data, payload_text));
  return page;
}

}  // namespace

absl::StatusOr<HtmlReportPage> BuildHtmlReport(const HtmlReportInput& in) {
  RETURN_IF_ERROR(CheckInput(in));
  return BuildPage(in);
}

absl::Status WriteHtmlReport(const std::string& path, const HtmlReportInput& input) {
  ASSIGN_OR_RETURN(auto page, BuildHtmlReport(input));
  return WriteStringAtomically(path, page.html);
}

}  // namespace surfinspect
