#include "core/report/html_sections.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_replace.h"
#include "core/report/html_escape.h"
#include "core/report/report_content.h"

namespace surfinspect {
namespace {

using nlohmann::json;

const json& At(const json& j, const char* key) {
  static const json kNull;
  return j.is_object() && j.contains(key) ? j[key] : kNull;
}

// A JSON value as text for people: strings as they are, numbers to 4
// decimals (integers whole), null as a dash.
std::string Text(const json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number_integer() || v.is_number_unsigned()) return v.dump();
  if (v.is_number()) return absl::StrFormat("%.4f", v.get<double>());
  if (v.is_null()) return "\u2013";
  return v.dump(-1, ' ', false, json::error_handler_t::replace);
}

std::string Td(const json& v) { return absl::StrCat("<td>", HtmlEscape(Text(v)), "</td>"); }

// A number the page's readers compare: its exact JSON text rides along.
std::string ValueRow(const std::string& label, const std::string& key, const json& v) {
  return absl::StrCat("<tr><th>", HtmlEscape(label), "</th><td data-key=\"", HtmlEscape(key),
                      "\" data-value=\"", HtmlEscape(v.dump()), "\">", HtmlEscape(Text(v)),
                      "</td></tr>\n");
}

std::string VerdictCell(const std::string& v) {
  const std::string s = v.empty() ? "?" : v;
  const char* cls = s == "pass" ? "pass" : s == "not_measured" ? "unmeasured" : "fail";
  return absl::StrCat("<td class=\"", cls, "\">", HtmlEscape(s), "</td>");
}

std::string Rows(const std::vector<ReportField>& fields, const std::string& prefix,
                 const std::string& suffix) {
  std::string out;
  for (const ReportField& f : fields)
    absl::StrAppend(&out, ValueRow(absl::StrCat(prefix, f.key, suffix), f.key, f.value));
  return out;
}

}  // namespace

std::string VerdictBanner(const InspectionReport& report, const HtmlReportContext& context) {
  const std::string verdict = report.verdict.empty() ? "?" : report.verdict;
  const bool pass = verdict == "pass";
  std::string out = absl::StrCat("<header id=\"verdict\" class=\"banner ", pass ? "pass" : "fail",
                                 "\" data-verdict=\"", HtmlEscape(verdict), "\">");
  absl::StrAppend(&out, "<span class=\"verdict\">", pass ? "PASS" : "FAIL", "</span>",
                  "<span class=\"part\">part <b id=\"part-id\">", HtmlEscape(context.part_id),
                  "</b></span>");
  if (!context.cell.empty())
    absl::StrAppend(&out, "<span class=\"cell\">cell ", HtmlEscape(context.cell), "</span>");
  absl::StrAppend(&out, "<span class=\"reason\">", HtmlEscape(report.tolerance.reason), "</span>");
  return out + "</header>\n";
}

// The printed reports' table (core/report/report_content.h), cell for
// cell; a cell's lines become line breaks.
std::string CharacteristicsTable(const InspectionReport& report) {
  std::vector<ReportCharacteristic> rows = report.characteristics;
  std::stable_partition(rows.begin(), rows.end(),
                        [](const ReportCharacteristic& c) { return !c.passed(); });
  std::string out = "<table id=\"characteristics\"><thead><tr>";
  for (const std::string& h : CharacteristicHeader()) absl::StrAppend(&out, "<th>", h, "</th>");
  out += "</tr></thead><tbody>\n";
  for (const ReportCharacteristic& c : rows) {
    absl::StrAppend(&out, "<tr title=\"", HtmlEscape(c.reason), "\">");
    const std::vector<std::string> cells = CharacteristicRow(c);
    for (std::size_t k = 0; k < cells.size(); ++k) {
      const std::string text = absl::StrReplaceAll(HtmlEscape(cells[k]), {{"\n", "<br>"}});
      absl::StrAppend(
          &out, k == kVerdictColumn ? VerdictCell(c.verdict) : absl::StrCat("<td>", text, "</td>"));
    }
    out += "</tr>\n";
  }
  return out + "</tbody></table>\n";
}

std::string DefectsTable(const InspectionReport& report) {
  if (report.defects.empty()) return "<p id=\"defects\" class=\"none\">no defects found</p>\n";
  std::string out =
      "<table id=\"defects\"><thead><tr><th>id</th><th>kind</th><th>peak mm</th><th>peak "
      "from</th><th>area mm\u00b2"
      "</th><th>extent mm</th><th>points</th><th>region</th></tr></thead><tbody>\n";
  for (const ReportDefect& d : report.defects) {
    absl::StrAppend(&out, "<tr class=\"defect\" tabindex=\"0\" data-defect=\"", d.id, "\">",
                    Td(d.id), Td(d.kind), Td(JsonNumber(d.peak_mm)), Td(d.peak_source),
                    Td(JsonNumber(d.area_mm2)), Td(JsonNumber(d.extent_mm)), Td(d.points),
                    Td(d.region), "</tr>\n");
  }
  return out + "</tbody></table>\n";
}

std::string AlignmentSection(const InspectionReport& report) {
  if (!report.alignment) return "";
  std::string out = "<h2>Alignment</h2>\n<p id=\"alignment-lines\">";
  for (const std::string& line : AlignmentLines(report.alignment))
    absl::StrAppend(&out, HtmlEscape(line), "<br>");
  out += "</p>\n";
  const ReportTable t = AlignmentTable(report.alignment);
  if (t.rows.empty()) return out;
  out += "<table id=\"alignment\"><thead><tr>";
  for (const std::string& h : t.header) absl::StrAppend(&out, "<th>", h, "</th>");
  out += "</tr></thead><tbody>\n";
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    out += "<tr>";
    for (std::size_t k = 0; k < t.rows[i].size(); ++k) {
      const std::string text = absl::StrReplaceAll(HtmlEscape(t.rows[i][k]), {{"\n", "<br>"}});
      absl::StrAppend(&out,
                      k == 2 ? absl::StrCat("<td class=\"", t.failed[i] ? "fail" : "pass", "\">")
                             : std::string("<td>"),
                      text, "</td>");
    }
    out += "</tr>\n";
  }
  return out + "</tbody></table>\n";
}

std::string StatisticsTable(const InspectionReport& report) {
  return absl::StrCat("<table id=\"statistics\"><tbody>\n",
                      Rows(PointCountFields(report), "", " points"),
                      Rows(StatisticsFields(report), "", ""),
                      Rows(ToleranceCountFields(report), "tolerance ", ""), "</tbody></table>\n");
}

std::string SettingsTable(const InspectionReport& report) {
  std::string out = "<table id=\"settings\"><tbody>\n";
  for (const ReportField& f : SettingsFields(report))
    absl::StrAppend(&out, "<tr><th>", HtmlEscape(f.key), "</th>", Td(f.value), "</tr>\n");
  absl::StrAppend(&out, "<tr><th>colour range mm</th>", Td(JsonNumber(report.color_range_mm)),
                  "</tr>\n</tbody></table>\n");
  return out;
}

std::string CalibrationTable(const HtmlReportContext& context) {
  if (context.viewpoints.empty())
    return "<p id=\"calibration\" class=\"none\">calibration status not known here</p>\n";
  std::string out =
      "<table id=\"calibration\"><thead><tr><th>viewpoint</th><th>status</th><th>RMS mm</th>"
      "<th>converged</th><th>warnings</th></tr></thead><tbody>\n";
  for (const ViewpointCalibration& v : context.viewpoints) {
    const json& warnings = At(v.quality, "warnings");
    std::string w;
    for (const json& x : warnings) absl::StrAppend(&w, w.empty() ? "" : "; ", Text(x));
    absl::StrAppend(&out, "<tr>", Td(v.name), "<td class=\"",
                    v.calibrated ? "pass\">calibrated" : "fail\">not calibrated", "</td>",
                    Td(At(v.quality, "rms_mm")), Td(At(v.quality, "converged")), Td(w), "</tr>\n");
  }
  return out + "</tbody></table>\n";
}

}  // namespace surfinspect
