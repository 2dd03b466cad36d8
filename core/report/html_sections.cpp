#include "core/report/html_sections.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/report/html_escape.h"

namespace surfinspect {
namespace {

using nlohmann::json;

const json& At(const json& j, const char* key) {
  static const json kNull;
  return j.is_object() && j.contains(key) ? j[key] : kNull;
}

double Num(const json& j, const char* key) {
  const json& v = At(j, key);
  return v.is_number() ? v.get<double>() : NAN;
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

// "+-t" for a symmetric band, "lower..upper" otherwise (mm).
std::string Band(const json& tolerance) {
  const double lo = Num(tolerance, "lower"), hi = Num(tolerance, "upper");
  if (lo == -hi) return absl::StrFormat("\u00b1%g", hi);
  const auto bound = [](double v) {
    return std::isnan(v) ? std::string("\u2013") : absl::StrFormat("%g", v);
  };
  return absl::StrCat(bound(lo), "..", bound(hi));
}

std::string Verdict(const json& v) {
  const std::string s = v.is_string() ? v.get<std::string>() : "?";
  return absl::StrCat("<td class=\"", s == "pass" ? "pass" : "fail", "\">", HtmlEscape(s), "</td>");
}

}  // namespace

std::string VerdictBanner(const json& report, const HtmlReportContext& context) {
  const std::string verdict = At(report, "verdict").is_string() ? report["verdict"] : "?";
  const bool pass = verdict == "pass";
  std::string out = absl::StrCat("<header id=\"verdict\" class=\"banner ", pass ? "pass" : "fail",
                                 "\" data-verdict=\"", HtmlEscape(verdict), "\">");
  absl::StrAppend(&out, "<span class=\"verdict\">", pass ? "PASS" : "FAIL", "</span>",
                  "<span class=\"part\">part <b id=\"part-id\">", HtmlEscape(context.part_id),
                  "</b></span>");
  if (!context.cell.empty())
    absl::StrAppend(&out, "<span class=\"cell\">cell ", HtmlEscape(context.cell), "</span>");
  const json& reason = At(At(report, "tolerance"), "reason");
  if (reason.is_string())
    absl::StrAppend(&out, "<span class=\"reason\">", HtmlEscape(reason.get<std::string>()),
                    "</span>");
  return out + "</header>\n";
}

std::string CharacteristicsTable(const json& report) {
  std::vector<json> rows;
  for (const json& c : At(report, "characteristics")) rows.push_back(c);
  std::stable_partition(rows.begin(), rows.end(),
                        [](const json& c) { return At(c, "verdict") != "pass"; });
  std::string out =
      "<table id=\"characteristics\"><thead><tr><th>name</th><th>type</th><th>verdict</th>"
      "<th>band mm</th><th>value/mean mm</th><th>min mm</th><th>max mm</th><th>within</th>"
      "<th>points</th></tr></thead><tbody>\n";
  for (const json& c : rows) {
    const json& value = At(c, "value_mm").is_null() ? At(c, "mean_mm") : At(c, "value_mm");
    const double within = Num(c, "fraction_within");
    absl::StrAppend(&out, "<tr title=\"", HtmlEscape(Text(At(c, "reason"))), "\">",
                    Td(At(c, "name")), Td(At(c, "type")), Verdict(At(c, "verdict")),
                    Td(Band(At(c, "tolerance_mm"))), Td(value), Td(At(c, "min_mm")),
                    Td(At(c, "max_mm")),
                    Td(std::isnan(within) ? json() : json(absl::StrFormat("%.2f%%", 100 * within))),
                    Td(At(c, "points")), "</tr>\n");
  }
  return out + "</tbody></table>\n";
}

std::string DefectsTable(const json& report) {
  const json& defects = At(report, "defects");
  if (defects.empty()) return "<p id=\"defects\" class=\"none\">no defects found</p>\n";
  std::string out =
      "<table id=\"defects\"><thead><tr><th>id</th><th>kind</th><th>peak mm</th><th>area mm\u00b2"
      "</th><th>extent mm</th><th>points</th><th>region</th></tr></thead><tbody>\n";
  for (const json& d : defects) {
    absl::StrAppend(&out, "<tr class=\"defect\" tabindex=\"0\" data-defect=\"",
                    HtmlEscape(Text(At(d, "id"))), "\">", Td(At(d, "id")), Td(At(d, "kind")),
                    Td(At(d, "peak_mm")), Td(At(d, "area_mm2")), Td(At(d, "extent_mm")),
                    Td(At(d, "points")), Td(At(d, "region")), "</tr>\n");
  }
  return out + "</tbody></table>\n";
}

std::string StatisticsTable(const json& report) {
  std::string out = "<table id=\"statistics\"><tbody>\n";
  const json& points = At(report, "points");
  for (const char* key : {"count", "valid", "matched"})
    absl::StrAppend(&out, ValueRow(absl::StrCat(key, " points"), key, At(points, key)));
  const json& st = At(report, "statistics");
  for (const char* key : {"min_mm", "max_mm", "mean_mm", "stddev_mm", "rms_mm", "p1_mm", "p5_mm",
                          "p50_mm", "p95_mm", "p99_mm"})
    absl::StrAppend(&out, ValueRow(key, key, At(st, key)));
  const json& tol = At(report, "tolerance");
  for (const char* key : {"within", "above", "below", "fraction_within"})
    absl::StrAppend(&out, ValueRow(absl::StrCat("tolerance ", key), key, At(tol, key)));
  return out + "</tbody></table>\n";
}

std::string SettingsTable(const json& report) {
  std::string out = "<table id=\"settings\"><tbody>\n";
  for (const char* group : {"settings", "inputs"}) {
    const json& g = At(report, group);
    if (!g.is_object()) continue;
    for (const auto& [key, value] : g.items())
      absl::StrAppend(&out, "<tr><th>", HtmlEscape(key), "</th>", Td(value), "</tr>\n");
  }
  absl::StrAppend(&out, "<tr><th>colour range mm</th>", Td(At(report, "color_range_mm")),
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
