#include "core/report/report_content.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace surfinspect {
namespace {

using nlohmann::json;

double Num(const json& j, const char* key) {
  const auto it = j.find(key);
  return it != j.end() && it->is_number() ? it->get<double>() : NAN;
}

std::string Str(const json& j, const char* key) {
  const auto it = j.find(key);
  return it != j.end() && it->is_string() ? it->get<std::string>() : std::string();
}

std::string Count(const json& j, const char* key) {
  const auto it = j.find(key);
  return it != j.end() && it->is_number_unsigned() ? absl::StrCat(it->get<std::size_t>()) : "-";
}

std::string Percent(double fraction) {
  return std::isfinite(fraction) ? absl::StrFormat("%.2f %%", 100 * fraction) : "-";
}

// A member object, or an empty one when absent (its values print as "-").
const json& Object(const json& j, const char* key) {
  static const json kEmpty = json::object();
  const auto it = j.find(key);
  return it != j.end() && it->is_object() ? *it : kEmpty;
}

void AddStatistics(const json& report, ReportContent& c) {
  const json& pts = Object(report, "points");
  const json& st = Object(report, "statistics");
  const json& tol = Object(report, "tolerance");
  c.statistics = {{"points", Count(pts, "count")},
                  {"valid", Count(pts, "valid")},
                  {"matched", Count(pts, "matched")},
                  {"tolerance", absl::StrCat("+-", FormatMm(c.tolerance_mm).substr(1), " mm")},
                  {"in tolerance", Percent(Num(tol, "fraction_within"))},
                  {"above/below", absl::StrCat(Count(tol, "above"), " / ", Count(tol, "below"))},
                  {"min", FormatMm(Num(st, "min_mm"))},
                  {"max", FormatMm(Num(st, "max_mm"))},
                  {"mean", FormatMm(Num(st, "mean_mm"))},
                  {"std dev", FormatMm(Num(st, "stddev_mm"))},
                  {"rms", FormatMm(Num(st, "rms_mm"))},
                  {"p1", FormatMm(Num(st, "p1_mm"))},
                  {"p5", FormatMm(Num(st, "p5_mm"))},
                  {"p50", FormatMm(Num(st, "p50_mm"))},
                  {"p95", FormatMm(Num(st, "p95_mm"))},
                  {"p99", FormatMm(Num(st, "p99_mm"))}};
}

// Failed rows first, each group in the report's order.
void AddCharacteristics(const json& list, ReportContent& c) {
  ReportTable& t = c.characteristics;
  t.header = {"characteristic", "type",   "verdict", "tolerance mm", "value / mean mm",
              "min mm",         "max mm", "in tol",  "points"};
  std::vector<std::size_t> order(list.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_partition(order.begin(), order.end(),
                        [&](std::size_t i) { return Str(list[i], "verdict") != "pass"; });
  for (std::size_t i : order) {
    const json& ch = list[i];
    const json& tol = ch.at("tolerance_mm");
    const bool point = Str(ch, "type") == "point";
    t.rows.push_back({Str(ch, "name"), Str(ch, "type"), Str(ch, "verdict"),
                      absl::StrCat(FormatMm(Num(tol, "lower")), " / ", FormatMm(Num(tol, "upper"))),
                      FormatMm(Num(ch, point ? "value_mm" : "mean_mm")),
                      FormatMm(Num(ch, "min_mm")), FormatMm(Num(ch, "max_mm")),
                      Percent(Num(ch, "fraction_within")), Count(ch, "points")});
    t.failed.push_back(Str(ch, "verdict") != "pass");
  }
}

void AddDefects(const json& list, ReportContent& c) {
  ReportTable& t = c.defects;
  t.header = {"defect",   "kind",      "region", "peak mm",
              "area mm2", "extent mm", "points", "centroid mm (part)"};
  for (const json& d : list) {
    Defect mark;
    mark.id = d.at("id").get<int>();
    const json& ctr = d.at("centroid_mm");
    mark.centroid_mm = {ctr.at(0).get<double>(), ctr.at(1).get<double>(), ctr.at(2).get<double>()};
    c.defect_marks.push_back(mark);
    t.rows.push_back({absl::StrCat(mark.id), Str(d, "kind"), Str(d, "region"),
                      FormatMm(Num(d, "peak_mm")), absl::StrFormat("%.1f", Num(d, "area_mm2")),
                      absl::StrFormat("%.1f", Num(d, "extent_mm")), Count(d, "points"),
                      absl::StrFormat("%.1f, %.1f, %.1f", mark.centroid_mm.x(),
                                      mark.centroid_mm.y(), mark.centroid_mm.z())});
    t.failed.push_back(true);
  }
}

void ReadHistogram(const json& h, Histogram& out) {
  out.min_mm = h.at("min_mm").get<double>();
  out.max_mm = h.at("max_mm").get<double>();
  out.counts = h.at("counts").get<std::vector<std::size_t>>();
  out.below_range = h.value("below_range", std::size_t{0});
  out.above_range = h.value("above_range", std::size_t{0});
}

}  // namespace

std::string FormatMm(double v) { return std::isfinite(v) ? absl::StrFormat("%+.3f", v) : "-"; }

absl::StatusOr<ReportContent> ReportContentFromJson(const nlohmann::json& report) {
  ReportContent c;
  try {
    const json& tol = report.at("tolerance");
    c.tolerance_mm = tol.at("band_mm").get<double>();
    c.color_range_mm = report.at("color_range_mm").get<double>();
    c.reason = Str(tol, "reason");
    // A plan's part verdict when there is one, else the +-tolerance verdict.
    c.verdict = report.contains("verdict") ? report.at("verdict").get<std::string>()
                                           : tol.at("verdict").get<std::string>();
    c.pass = c.verdict == "pass";
    AddStatistics(report, c);
    if (report.contains("histogram")) ReadHistogram(report.at("histogram"), c.histogram);
    if (report.contains("characteristics")) AddCharacteristics(report["characteristics"], c);
    if (report.contains("defects")) AddDefects(report["defects"], c);
  } catch (const json::exception& e) {
    return absl::DataLossError(absl::StrCat("report: ", e.what()));
  }
  if (!(c.tolerance_mm > 0) || !(c.color_range_mm > 0))
    return absl::DataLossError("report: tolerance.band_mm and color_range_mm must be > 0");
  return c;
}

}  // namespace surfinspect
