#include "core/report/html_report.h"

#include <chrono>
#include <cmath>
#include <cstring>

#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "core/io/atomic_file.h"
#include "core/report/html_escape.h"
#include "core/report/html_histogram.h"
#include "core/report/viewer_assets.h"

namespace surfinspect {
namespace {

using nlohmann::json;

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "the page reads the payload as little-endian typed arrays");

// Appends `data` to `blob` at a multiple of 4 bytes; returns [offset, bytes].
template <typename T>
json Append(std::string& blob, const std::vector<T>& data) {
  blob.resize((blob.size() + 3) / 4 * 4, '\0');
  const std::size_t offset = blob.size(), bytes = data.size() * sizeof(T);
  blob.resize(offset + bytes);
  if (bytes) std::memcpy(blob.data() + offset, data.data(), bytes);
  return json::array({offset, bytes});
}

json Vec(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

// What the viewer reads: scale, palette, the payload's layout, defects.
json ViewerData(const json& report, const HtmlReportContext& ctx, const DeviationPalette& palette,
                const HtmlPayload& p, std::string& blob) {
  json colors = json::array();
  for (const Rgb& c : palette.colors) colors.insert(colors.end(), {c.r, c.g, c.b});
  json data = {{"part_id", ctx.part_id},
               {"cell", ctx.cell},
               {"tolerance_mm", palette.tolerance_mm},
               {"range_mm", palette.range_mm},
               {"palette", colors},
               {"three", std::string(GetViewerAssets().three_version)}};
  data["points"] = {{"input", p.input_points},
                    {"finite", p.finite_points},
                    {"shown", p.positions.size()},
                    {"thinned", p.thinned},
                    {"cell_mm", p.cell_mm},
                    {"per_cell", p.per_cell},
                    {"min", Vec(p.positions.min)},
                    {"step", Vec(p.positions.step)},
                    {"deviation_step_mm", p.deviation_step_mm},
                    {"positions", Append(blob, p.positions.xyz)},
                    {"deviations", Append(blob, p.deviation)},
                    {"palette_index", Append(blob, p.palette_index)}};
  data["mesh"] = nullptr;
  data["mesh_omitted"] = p.mesh_omitted;
  if (!p.mesh_triangles.empty())
    data["mesh"] = {{"vertices", p.mesh_vertices.size()},
                    {"triangles", p.mesh_triangles.size() / 3},
                    {"min", Vec(p.mesh_vertices.min)},
                    {"step", Vec(p.mesh_vertices.step)},
                    {"positions", Append(blob, p.mesh_vertices.xyz)},
                    {"indices", Append(blob, p.mesh_triangles)}};
  data["defects"] = json::array();
  if (report.contains("defects") && report["defects"].is_array())
    for (const json& d : report["defects"])
      if (d.is_object())
        data["defects"].push_back({{"id", d.value("id", json())},
                                   {"kind", d.value("kind", json())},
                                   {"centroid_mm", d.value("centroid_mm", json())},
                                   {"extent_mm", d.value("extent_mm", json())},
                                   {"peak_mm", d.value("peak_mm", json())},
                                   {"region", d.value("region", json())}});
  return data;
}

std::string DataUrl(absl::string_view base64) {
  return absl::StrCat("data:text/javascript;base64,", base64);
}

std::string Head(const HtmlReportContext& ctx, const json& report) {
  const ViewerAssets& a = GetViewerAssets();
  const json imports = {
      {"imports",
       {{"three", DataUrl(a.three_module_base64)},
        {"three/addons/controls/OrbitControls.js", DataUrl(a.orbit_controls_base64)}}}};
  const std::string verdict = report.contains("verdict") && report["verdict"].is_string()
                                  ? report["verdict"].get<std::string>()
                                  : "?";
  return absl::StrCat("<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n",
                      "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n",
                      "<title>surfinspect report: ", HtmlEscape(ctx.part_id), " (",
                      HtmlEscape(verdict), ")</title>\n<style>\n", a.viewer_css, "</style>\n",
                      "<script type=\"importmap\">", JsonForScript(imports), "</script>\n",
                      "</head><body>\n");
}

std::string ViewerPane() {
  std::string views;
  for (const char* v : {"iso", "top", "bottom", "front", "back", "left", "right"})
    absl::StrAppend(&views, "<button type=\"button\" data-view=\"", v, "\">", v, "</button>");
  return absl::StrCat(
      "<section id=\"viewer-pane\"><div id=\"toolbar\">", views,
      "<label><input type=\"checkbox\" id=\"mesh-toggle\" checked> CAD mesh</label>"
      "<label><input type=\"checkbox\" id=\"defect-toggle\" checked> defects</label></div>\n"
      "<div id=\"viewer\"><canvas id=\"legend\" width=\"120\" height=\"320\"></canvas>"
      "<div id=\"labels\"></div><div id=\"hover\" hidden></div>"
      "<noscript><p>The 3D view needs JavaScript; the tables work without it.</p></noscript>"
      "</div>\n<p id=\"viewer-note\"></p></section>\n");
}

std::string SidePane(const json& report, const HtmlReportContext& ctx,
                     const DeviationPalette& palette) {
  return absl::StrCat("<aside id=\"side\">\n<h2>Characteristics</h2>\n",
                      CharacteristicsTable(report), "<h2>Defects</h2>\n", DefectsTable(report),
                      "<h2>Histogram</h2>\n", HistogramSvg(report, palette),
                      "<h2>Statistics (all points)</h2>\n", StatisticsTable(report),
                      "<h2>Calibration</h2>\n", CalibrationTable(ctx), "<h2>Settings</h2>\n",
                      SettingsTable(report), "</aside>\n");
}

absl::Status CheckInput(const HtmlReportInput& in) {
  if (!in.report || !in.report->is_object())
    return absl::InvalidArgumentError("HTML report: no report object");
  if (!in.points_in_part || !in.deviation_mm)
    return absl::InvalidArgumentError("HTML report: no points or deviations");
  const json& r = *in.report;
  if (!r.contains("tolerance") || !r["tolerance"].contains("band_mm") ||
      !r["tolerance"]["band_mm"].is_number() || !(r["tolerance"]["band_mm"].get<double>() > 0))
    return absl::InvalidArgumentError("HTML report: report lacks tolerance.band_mm");
  if (!r.contains("color_range_mm") || !r["color_range_mm"].is_number())
    return absl::InvalidArgumentError("HTML report: report lacks color_range_mm");
  return absl::OkStatus();
}

absl::StatusOr<HtmlReportPage> BuildPage(const HtmlReportInput& in) {
  const json& report = *in.report;
  const auto t0 = std::chrono::steady_clock::now();
  const DeviationPalette palette = MakeDeviationPalette(
      report["tolerance"]["band_mm"].get<double>(), report["color_range_mm"].get<double>());
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
      Head(in.context, report), VerdictBanner(report, in.context), "<main>\n", ViewerPane(),
      SidePane(report, in.context, palette), "</main>\n<footer>surfinspect report, three.js ",
      GetViewerAssets().three_version,
      "</footer>\n<script type=\"application/json\" id=\"si-data\">", JsonForScript(data),
      "</script>\n<script type=\"application/octet-stream\" id=\"si-payload\">", payload_text,
      "</script>\n<script type=\"module\" src=\"", DataUrl(GetViewerAssets().viewer_base64),
      "\"></script>\n</body></html>\n");
  return page;
}

}  // namespace

absl::StatusOr<HtmlReportPage> BuildHtmlReport(const HtmlReportInput& in) {
  if (auto st = CheckInput(in); !st.ok()) return st;
  try {
    return BuildPage(in);
  } catch (const json::exception& e) {  // a report field of an unexpected type
    return absl::InvalidArgumentError(absl::StrCat("HTML report: malformed report: ", e.what()));
  }
}

absl::Status WriteHtmlReport(const std::string& path, const HtmlReportInput& input) {
  auto page = BuildHtmlReport(input);
  if (!page.ok()) return page.status();
  return WriteStringAtomically(path, page->html);
}

}  // namespace surfinspect
