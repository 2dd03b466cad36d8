#include "core/report/report_content.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"

namespace surfinspect {
namespace {

std::string Count(std::size_t n) { return absl::StrCat(n); }

std::string Percent(double fraction) {
  return std::isfinite(fraction) ? absl::StrFormat("%.2f %%", 100 * fraction) : "-";
}

// Counts that are all zero come from a report without its "points"
// section (a part with no point at all is refused before a report): dashes.
std::string CountOrDash(std::size_t n, bool known) { return known ? Count(n) : "-"; }

void AddStatistics(const InspectionReport& r, ReportContent& c) {
  const ErrorMapStats& st = r.stats;
  const bool counted = st.count > 0 || st.valid > 0 || st.matched > 0;
  const ReportTolerance& tol = r.tolerance;
  c.statistics = {{"points", CountOrDash(st.count, counted)},
                  {"valid", CountOrDash(st.valid, counted)},
                  {"matched", CountOrDash(st.matched, counted)},
                  {"tolerance", absl::StrCat("+-", FormatMm(c.tolerance_mm).substr(1), " mm")},
                  {"in tolerance", Percent(tol.fraction_within)},
                  {"above/below", absl::StrCat(Count(tol.above), " / ", Count(tol.below))},
                  {"min", FormatMm(st.min_mm)},
                  {"max", FormatMm(st.max_mm)},
                  {"mean", FormatMm(st.mean_mm)},
                  {"std dev", FormatMm(st.stddev_mm)},
                  {"rms", FormatMm(st.rms_mm)},
                  {"p1", FormatMm(st.p1_mm)},
                  {"p5", FormatMm(st.p5_mm)},
                  {"p50", FormatMm(st.p50_mm)},
                  {"p95", FormatMm(st.p95_mm)},
                  {"p99", FormatMm(st.p99_mm)}};
}

// The labels of a hole's quantities, for every renderer.
constexpr char kDiameter[] = "\u00d8", kWidth[] = "W", kLength[] = "L", kPosition[] = "TP";

std::string Band(const ToleranceBand& b) {
  return absl::StrCat(FormatMm(b.lower_mm), " / ", FormatMm(b.upper_mm));
}

// "Ø 8.012 (+0.012)"; "-" when not measured.
std::string Size(const char* label, double measured_mm, double deviation_mm) {
  if (!std::isfinite(measured_mm)) return "-";
  return absl::StrFormat("%s %.3f (%s)", label, measured_mm, FormatMm(deviation_mm));
}

std::vector<std::string> HoleRow(const ReportCharacteristic& c) {
  const bool slot = c.type == "slot";
  const char* size = slot ? kWidth : kDiameter;
  const std::string zone = absl::StrFormat("%s %.3f", kPosition, c.position_tolerance_mm);
  std::string band = absl::StrCat(size, " ", Band(c.tolerance), "\n");
  std::string value = "-";
  if (c.measured()) {
    value = absl::StrCat(Size(size, c.measured_diameter_mm, c.diameter_deviation_mm), "\n");
    if (slot)
      absl::StrAppend(&value, Size(kLength, c.measured_length_mm, c.length_deviation_mm), "\n");
    absl::StrAppend(&value, absl::StrFormat("%s %.3f / %.3f", kPosition, c.true_position_mm,
                                            c.position_tolerance_mm));
  }
  if (slot) absl::StrAppend(&band, kLength, " ", Band(c.length_tolerance), "\n");
  const std::string arc = std::isfinite(c.arc_coverage_deg)
                              ? absl::StrFormat("arc %.0f\u00b0", c.arc_coverage_deg)
                              : "-";
  return {c.name, c.type, c.verdict, band + zone,     value,
          "-",    "-",    arc,       Count(c.points), CoverageText(c)};
}

// Failed rows first, each group in the report's order.
void AddCharacteristics(const std::vector<ReportCharacteristic>& list, ReportContent& c) {
  ReportTable& t = c.characteristics;
  t.header = CharacteristicHeader();
  std::vector<std::size_t> order(list.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_partition(order.begin(), order.end(),
                        [&](std::size_t i) { return !list[i].passed(); });
  for (std::size_t i : order) {
    t.rows.push_back(CharacteristicRow(list[i]));
    t.failed.push_back(!list[i].passed());
  }
}

void AddDefects(const std::vector<ReportDefect>& list, ReportContent& c) {
  ReportTable& t = c.defects;
  t.header = {"defect",   "kind",      "region", "peak mm",           "peak from",
              "area mm2", "extent mm", "points", "centroid mm (part)"};
  for (const ReportDefect& d : list) {
    Defect mark;
    mark.id = d.id;
    mark.centroid_mm = d.centroid_mm;
    c.defect_marks.push_back(mark);
    t.rows.push_back({absl::StrCat(d.id), d.kind, d.region, FormatMm(d.peak_mm), d.peak_source,
                      absl::StrFormat("%.1f", d.area_mm2), absl::StrFormat("%.1f", d.extent_mm),
                      Count(d.points),
                      absl::StrFormat("%.1f, %.1f, %.1f", d.centroid_mm.x(), d.centroid_mm.y(),
                                      d.centroid_mm.z())});
    t.failed.push_back(true);
  }
}

}  // namespace

const std::vector<std::string>& CharacteristicHeader() {
  static const std::vector<std::string> kHeader = {
      "characteristic", "type",   "verdict",      "tolerance mm", "value / mean mm",
      "min mm",         "max mm", "in tol / arc", "points",       "coverage"};
  return kHeader;
}

std::vector<std::string> CharacteristicRow(const ReportCharacteristic& c) {
  if (c.is_hole()) return HoleRow(c);
  return {c.name,
          c.type,
          c.verdict,
          Band(c.tolerance),
          FormatMm(c.has_value() ? c.value_mm : c.mean_mm),
          FormatMm(c.min_mm),
          FormatMm(c.max_mm),
          Percent(c.fraction_within),
          Count(c.points),
          CoverageText(c)};
}

HoleVerdicts HoleVerdictsOf(const ReportCharacteristic& c) {
  if (!c.measured())
    return {"not_measured", c.type == "slot" ? "not_measured" : "", "not_measured"};
  auto within = [](const ToleranceBand& band, double deviation_mm) {
    return band.Contains(static_cast<float>(deviation_mm)) ? "pass" : "fail";
  };
  HoleVerdicts v;
  v.size = within(c.tolerance, c.diameter_deviation_mm);
  if (c.type == "slot") v.length = within(c.length_tolerance, c.length_deviation_mm);
  v.position = c.true_position_mm <= c.position_tolerance_mm ? "pass" : "fail";
  return v;
}

std::string CoverageText(const ReportCharacteristic& c) {
  if (std::isnan(c.coverage)) return "-";
  std::string s = absl::StrFormat("%.1f%%", 100 * c.coverage);
  if (c.min_coverage > 0)
    absl::StrAppend(&s, absl::StrFormat(" (min %.0f%%)", 100 * c.min_coverage));
  return s;
}

std::string FormatMm(double v) { return std::isfinite(v) ? absl::StrFormat("%+.3f", v) : "-"; }

absl::StatusOr<ReportContent> ReportContentFrom(const InspectionReport& report) {
  ReportContent c;
  c.tolerance_mm = report.tolerance.band_mm;
  c.color_range_mm = report.color_range_mm;
  if (!(c.tolerance_mm > 0) || !(c.color_range_mm > 0))
    return absl::DataLossError("report: tolerance.band_mm and color_range_mm must be > 0");
  c.reason = report.tolerance.reason;
  // A plan's part verdict when there is one, else the +-tolerance verdict.
  c.verdict = !report.verdict.empty() ? report.verdict : report.tolerance.verdict;
  if (c.verdict.empty()) return absl::DataLossError("report: no verdict (nor tolerance.verdict)");
  c.pass = c.verdict == "pass";
  AddStatistics(report, c);
  c.histogram = report.histogram;
  AddCharacteristics(report.characteristics, c);
  AddDefects(report.defects, c);
  c.alignment_lines = AlignmentLines(report.alignment);
  c.alignment = AlignmentTable(report.alignment);
  return c;
}

std::vector<std::string> AlignmentLines(const std::optional<ReportAlignment>& a) {
  if (!a) return {};
  std::vector<std::string> lines;
  if (a->aligned)
    lines.push_back(absl::StrFormat(
        "%s: corrected %.3f mm / %.4f deg (allowed %.3g mm / %.3g deg), rms %.4f -> %.4f mm",
        a->mode, a->correction_mm, a->correction_deg, a->max_correction_mm, a->max_correction_deg,
        a->rms_before_mm, a->rms_after_mm));
  if (!a->failure.empty()) lines.push_back(absl::StrCat(a->mode, " failed: ", a->failure));
  if (!a->note.empty()) lines.push_back(absl::StrCat("note: ", a->note));
  return lines;
}

const std::vector<std::string>& AlignmentHeader() {
  static const std::vector<std::string> header = {"reference", "kind",     "measured", "locks",
                                                  "before mm", "after mm", "points"};
  return header;
}

ReportTable AlignmentTable(const std::optional<ReportAlignment>& a) {
  ReportTable t;
  if (!a) return t;
  t.header = AlignmentHeader();
  for (const ReportAlignmentReference& r : a->references) {
    std::vector<std::string> locks, before, after;
    for (const ReportLockedDirection& d : r.locked) {
      locks.push_back(
          absl::StrFormat("(%.3f, %.3f, %.3f)", d.direction.x(), d.direction.y(), d.direction.z()));
      before.push_back(FormatMm(d.before_mm));
      after.push_back(FormatMm(d.after_mm));
    }
    t.rows.push_back({r.name, r.kind, r.measured ? "yes" : "no", absl::StrJoin(locks, "\n"),
                      absl::StrJoin(before, "\n"), absl::StrJoin(after, "\n"),
                      absl::StrCat(r.points)});
    t.failed.push_back(!r.measured);
  }
  return t;
}

}  // namespace surfinspect
