#include "core/pipeline/inspection_report.h"  // and core/types/json_fields.h

#include "core/pipeline/report_results.h"

namespace surfinspect {
namespace {

using nlohmann::json;

// Each part of the report is listed once, by a Visit function that names its
// fields in reading order (core/types/json_fields.h): the same function
// writes, reads and lists it, so a key exists in one place. R is the part's
// struct, const when written.

// A hole's or slot's own fields; a slot names its size width, not diameter.
template <typename V, typename R>
void VisitHole(V& v, R& c) {
  const bool slot = c.type == "slot";
  v("measured_position_mm", c.measured_position_mm);
  v("position_deviation_mm", c.position_deviation_mm);
  v("true_position_mm", c.true_position_mm);
  v("position_tolerance_mm", c.position_tolerance_mm);
  v(slot ? "measured_width_mm" : "measured_diameter_mm", c.measured_diameter_mm);
  v(slot ? "width_deviation_mm" : "diameter_deviation_mm", c.diameter_deviation_mm);
  if (slot) {
    v("measured_length_mm", c.measured_length_mm);
    v("length_deviation_mm", c.length_deviation_mm);
    v.Object("length_tolerance_mm", c.length_tolerance, [](auto& w, auto& b) { VisitBand(w, b); });
  }
  v("form_mm", c.form_mm);
  v("arc_coverage_deg", c.arc_coverage_deg);
  v("pixel_pitch_mm", c.pixel_pitch_mm);
}

template <typename V, typename R>
void VisitCharacteristic(V& v, R& c) {
  v.Require("name");
  v("name", c.name);
  v("type", c.type);  // read before the fields that depend on it
  v("verdict", c.verdict);
  v("reason", c.reason);
  v.Object("tolerance_mm", c.tolerance, [](auto& w, auto& b) { VisitBand(w, b); });
  v("coverage", c.coverage);
  v("min_coverage", c.min_coverage);
  v("points", c.points);
  v("min_mm", c.min_mm);
  v("max_mm", c.max_mm);
  v("mean_mm", c.mean_mm);
  v("stddev_mm", c.stddev_mm);
  v("rms_mm", c.rms_mm);
  v("fraction_within", c.fraction_within);
  if (c.has_value())
    v("value_mm", c.value_mm);
  else if (c.is_hole())
    VisitHole(v, c);
  else
    v("allowed_fraction_outside", c.allowed_fraction_outside);
}

template <typename V, typename R>
void VisitDefect(V& v, R& d) {
  v.Require("id");
  v("id", d.id);
  v("kind", d.kind);
  v("centroid_mm", d.centroid_mm);
  v("area_mm2", d.area_mm2);
  v("extent_mm", d.extent_mm);
  v("peak_mm", d.peak_mm);
  v("peak_source", d.peak_source);
  v("measured_extreme_mm", d.measured_extreme_mm);
  v("noise_mm", d.noise_mm);
  v("points", d.points);
  v("region", d.region);
}

template <typename V, typename R>
void VisitSettings(V& v, R& s) {
  v("tolerance_mm", s.tolerance_mm);
  v("max_distance_mm", s.max_distance_mm);  // null = unlimited
  v("allowed_fraction_outside", s.allowed_fraction_outside);
  v("histogram_bins", s.histogram_bins);
  v("split_components", s.split_components);
}

template <typename V, typename R>
void VisitPointCounts(V& v, R& s) {
  v("count", s.count);
  v("valid", s.valid);
  v("matched", s.matched);
}

// In the order people read them: extremes, moments, percentiles.
template <typename V, typename R>
void VisitStatistics(V& v, R& s) {
  v("min_mm", s.min_mm);
  v("max_mm", s.max_mm);
  v("mean_mm", s.mean_mm);
  v("stddev_mm", s.stddev_mm);
  v("rms_mm", s.rms_mm);
  v("p1_mm", s.p1_mm);
  v("p5_mm", s.p5_mm);
  v("p50_mm", s.p50_mm);
  v("p95_mm", s.p95_mm);
  v("p99_mm", s.p99_mm);
}

template <typename V, typename R>
void VisitToleranceCounts(V& v, R& t) {
  v("within", t.within);
  v("above", t.above);
  v("below", t.below);
  v("fraction_within", t.fraction_within);
}

template <typename V, typename R>
void VisitTolerance(V& v, R& r) {
  v("band_mm", r.tolerance.band_mm);
  VisitToleranceCounts(v, r.tolerance);
  v("fraction_outside", r.tolerance.fraction_outside);
  v.Derived("allowed_fraction_outside", JsonNumber(r.settings.allowed_fraction_outside));
  v("verdict", r.tolerance.verdict);
  v("reason", r.tolerance.reason);
}

template <typename V, typename R>
void VisitHistogram(V& v, R& h) {
  v("min_mm", h.min_mm);
  v("max_mm", h.max_mm);
  v.Derived("bin_width_mm", JsonNumber(h.bin_width_mm()));
  v("counts", h.counts);
  v("below_range", h.below_range);
  v("above_range", h.above_range);
}

template <typename V, typename R>
void VisitComponents(V& v, R& c) {
  auto stats = [](auto& w, auto& s) {
    w("mean_mm", s.mean_mm);
    w("rms_mm", s.rms_mm);
    w("min_mm", s.min_mm);
    w("max_mm", s.max_mm);
  };
  v.Derived("frame", "part");
  v.Object("x", c[0], stats);
  v.Object("y", c[1], stats);
  v.Object("z", c[2], stats);
  v.Object("normal", c[3], stats);
}

template <typename V, typename R>
void VisitTiming(V& v, R& t) {
  v("query_seconds", t.query_seconds);
  v("order_seconds", t.order_seconds);
  v("statistics_seconds", t.statistics_seconds);
  v("certified_points", t.certified_points);
  v("hint_alone_points", t.hint_alone_points);
  v("read_seconds", t.read_seconds);
  v("build_seconds", t.build_seconds);
  v("plan_seconds", t.plan_seconds);
  v("png_seconds", t.png_seconds);
  v("write_seconds", t.write_seconds);
  v("total_seconds", t.total_seconds);
}

template <typename V, typename R>
void VisitInputs(V& v, R& in) {
  v("cloud", in.cloud);
  v("mesh", in.mesh);
  v("world_from_part", in.world_from_part);
}

template <typename V, typename R>
void VisitMesh(V& v, R& m) {
  v("triangles", m.triangles);
  v("boundary_edges", m.boundary_edges);
  v("nonmanifold_edges", m.nonmanifold_edges);
  v("degenerate_triangles", m.degenerate_triangles);
}

template <typename V, typename R>
void VisitCad(V& v, R& c) {
  v("source", c.source);
  v("format", c.format);
  v("declared_unit", c.declared_unit);
  v("chord_tolerance_mm", c.chord_tolerance_mm);
  v("tessellation_error_mm", c.tessellation_error_mm);
  v("tolerance_held", c.tolerance_held);
}

template <typename V, typename R>
void VisitInputUnits(V& v, R& u) {
  v("cloud", u.cloud);
  v("cloud_stated", u.cloud_stated);
  v("mesh", u.mesh);
  v("mesh_stated", u.mesh_stated);
  v("doubts", u.doubts);
}

// A Visit function as the argument Object and List take.
#define SURFINSPECT_VISIT(F) [](auto& v, auto& part) { F(v, part); }

template <typename V, typename R>
void VisitReport(V& v, R& r) {
  v.Derived("units", "mm");
  v.Derived("sign", "+ above the CAD surface (side of the CCW face normals), - below");
  v.Object("settings", r.settings, SURFINSPECT_VISIT(VisitSettings));
  v.Object("points", r.stats, [](auto& w, auto& s) {
    VisitPointCounts(w, s);
    w.Derived("unmatched_valid", s.valid - s.matched);
  });
  v.Object("statistics", r.stats, SURFINSPECT_VISIT(VisitStatistics));
  v.Object("tolerance", r, SURFINSPECT_VISIT(VisitTolerance));
  v.Object("histogram", r.histogram, SURFINSPECT_VISIT(VisitHistogram));
  v("color_range_mm", r.color_range_mm);
  v.Object("components", r.components, SURFINSPECT_VISIT(VisitComponents));
  v.Object("timing", r.timing, SURFINSPECT_VISIT(VisitTiming));
  // A report without a plan (no schema) has no plan sections; a reader
  // takes them wherever they are.
  if (V::kReads || !r.schema.empty()) {
    v("schema", r.schema);
    v("verdict", r.verdict);
    v.List("characteristics", r.characteristics, SURFINSPECT_VISIT(VisitCharacteristic));
    v.List("defects", r.defects, SURFINSPECT_VISIT(VisitDefect));
  }
  VisitReportSections(v, r.sections);
  VisitReportCoverage(v, r.coverage);
  VisitReportAlignment(v, r.alignment);
  v.Object("inputs", r.inputs, SURFINSPECT_VISIT(VisitInputs));
  v.Object("mesh", r.mesh, SURFINSPECT_VISIT(VisitMesh));
  v.Object("cad", r.cad, SURFINSPECT_VISIT(VisitCad));
  v.Object("input_units", r.input_units, SURFINSPECT_VISIT(VisitInputUnits));
  if (V::kReads || !r.output_frame.empty()) v("output_frame", r.output_frame);
}

template <typename R, typename F>
std::vector<ReportField> ListOf(const R& part, F visit) {
  JsonLister lister;
  visit(lister, part);
  return std::move(lister.fields);
}

json EncodeCharacteristic(const ReportCharacteristic& c) {
  JsonWriter w;
  VisitCharacteristic(w, c);
  return std::move(w.out);
}

json EncodeDefect(const ReportDefect& d) {
  JsonWriter w;
  VisitDefect(w, d);
  return std::move(w.out);
}

}  // namespace

ReportCad ReportCadOf(const CadReport& r) {
  return {r.source,        r.format, r.declared_unit, r.chord_tolerance_mm, r.tessellation_error_mm,
          r.tolerance_held};
}

json EncodeReport(const InspectionReport& report) {
  JsonWriter w;
  VisitReport(w, report);
  return std::move(w.out);
}

absl::StatusOr<InspectionReport> DecodeReport(const json& j) {
  InspectionReport report;
  JsonReader r(j, "report");
  VisitReport(r, report);
  if (!r.status().ok()) return r.status();
  if (absl::Status s = CheckReportSections(report.sections); !s.ok()) return s;
  if (absl::Status s = CheckReportCoverage(report.coverage); !s.ok()) return s;
  if (absl::Status s = CheckReportAlignment(report.alignment); !s.ok()) return s;
  return report;
}

std::string ReportText(const InspectionReport& report) {
  return EncodeReport(report).dump(2) + "\n";
}

absl::StatusOr<InspectionReport> ParseReport(const std::string& text) {
  const json j = json::parse(text, nullptr, false);
  if (j.is_discarded()) return absl::DataLossError("report: not valid JSON");
  return DecodeReport(j);
}

std::vector<ReportField> PointCountFields(const InspectionReport& r) {
  return ListOf(r.stats, SURFINSPECT_VISIT(VisitPointCounts));
}

std::vector<ReportField> StatisticsFields(const InspectionReport& r) {
  return ListOf(r.stats, SURFINSPECT_VISIT(VisitStatistics));
}

std::vector<ReportField> ToleranceCountFields(const InspectionReport& r) {
  return ListOf(r.tolerance, SURFINSPECT_VISIT(VisitToleranceCounts));
}

std::vector<ReportField> SettingsFields(const InspectionReport& r) {
  std::vector<ReportField> out;
  // Each group's fields, keys after `prefix`: the settings and inputs bare,
  // then what the numbers rest on (the CAD's measured tessellation error,
  // the units read, with any doubt) under their report.json keys.
  auto add = [&](const std::string& prefix, const auto& part, auto visit) {
    JsonWriter w;
    visit(w, part);
    for (const auto& [key, value] : w.out.items()) out.push_back({prefix + key, value});
  };
  add("", r.settings, SURFINSPECT_VISIT(VisitSettings));
  if (r.inputs) add("", *r.inputs, SURFINSPECT_VISIT(VisitInputs));
  if (r.cad) add("cad.", *r.cad, SURFINSPECT_VISIT(VisitCad));
  if (r.input_units) add("input_units.", *r.input_units, SURFINSPECT_VISIT(VisitInputUnits));
  return out;
}

bool ReportCharacteristic::operator==(const ReportCharacteristic& o) const {
  return EncodeCharacteristic(*this) == EncodeCharacteristic(o);
}

bool ReportDefect::operator==(const ReportDefect& o) const {
  return EncodeDefect(*this) == EncodeDefect(o);
}

InspectionReport ErrorMapReport(const ErrorMapResult& r, const ErrorMapSettings& settings) {
  InspectionReport out;
  out.settings = {settings.tolerance_mm, settings.max_distance_mm,
                  settings.allowed_fraction_outside, settings.histogram_bins,
                  settings.split_components};
  out.stats = r.stats;
  const Verdict& v = r.verdict;
  out.tolerance = {
      r.tolerance_mm,           v.within, v.above, v.below, v.fraction_within, v.fraction_outside,
      v.pass ? "pass" : "fail", v.reason};
  out.histogram = r.histogram;
  out.color_range_mm = r.color_range_mm;
  if (!r.deviation_xyz_mm.empty()) out.components = r.component_stats;
  out.timing.query_seconds = r.query_seconds;
  out.timing.order_seconds = r.order_seconds;
  out.timing.statistics_seconds = r.statistics_seconds;
  out.timing.certified_points = r.certified_points;
  out.timing.hint_alone_points = r.hint_alone_points;
  return out;
}

InspectionReport MakeInspectionReport(const ErrorMapResult& error_map,
                                      const ErrorMapSettings& settings,
                                      const PlanOutcome& outcome) {
  InspectionReport out = ErrorMapReport(error_map, settings);
  out.schema = kReportSchema;
  out.verdict = outcome.pass() ? "pass" : "fail";
  for (const CharacteristicResult& c : outcome.characteristics.characteristics)
    out.characteristics.push_back(ReportCharacteristicOf(c));
  for (const Defect& d : outcome.defects.defects) out.defects.push_back(ReportDefectOf(d));
  out.sections = ReportSectionsOf(outcome);
  out.coverage = ReportCoverageOf(outcome);
  out.alignment = ReportAlignmentOf(outcome);
  return out;
}

json ErrorMapReportJson(const ErrorMapResult& result, const ErrorMapSettings& settings) {
  return EncodeReport(ErrorMapReport(result, settings));
}

json CharacteristicsJson(const CharacteristicsResult& result) {
  json list = json::array();
  for (const CharacteristicResult& c : result.characteristics)
    list.push_back(EncodeCharacteristic(ReportCharacteristicOf(c)));
  return list;
}

json EncodeDefects(const std::vector<ReportDefect>& defects) {
  json list = json::array();
  for (const ReportDefect& d : defects) list.push_back(EncodeDefect(d));
  return list;
}

json DefectsJson(const DefectsResult& result) {
  std::vector<ReportDefect> defects;
  for (const Defect& d : result.defects) defects.push_back(ReportDefectOf(d));
  return EncodeDefects(defects);
}

std::string ErrorMapReportText(const ErrorMapResult& result, const ErrorMapSettings& settings,
                               const PlanOutcome& outcome) {
  return ReportText(MakeInspectionReport(result, settings, outcome));
}

}  // namespace surfinspect
