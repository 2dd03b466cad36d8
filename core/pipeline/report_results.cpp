#include "core/pipeline/report_results.h"

namespace surfinspect {

ReportCharacteristic ReportCharacteristicOf(const CharacteristicResult& c) {
  ReportCharacteristic out;
  out.name = c.name;
  out.type = CharacteristicTypeName(c.type);
  out.verdict = VerdictName(c);
  out.reason = c.reason;
  out.coverage = c.coverage;
  out.min_coverage = c.min_coverage;
  out.tolerance = c.tolerance;
  out.points = c.points;
  out.min_mm = c.min_mm;
  out.max_mm = c.max_mm;
  out.mean_mm = c.mean_mm;
  out.stddev_mm = c.stddev_mm;
  out.rms_mm = c.rms_mm;
  out.fraction_within = c.fraction_within;
  out.value_mm = c.value_mm;
  out.allowed_fraction_outside = c.allowed_fraction_outside;
  if (c.is_hole()) {
    const HoleMeasurement& h = c.hole;
    out.measured_position_mm = h.measured_position_mm;
    out.position_deviation_mm = h.position_deviation_mm;
    out.true_position_mm = h.true_position_mm;
    out.position_tolerance_mm = c.position_tolerance_mm;
    out.measured_diameter_mm = h.diameter_mm;
    out.diameter_deviation_mm = h.diameter_deviation_mm;
    out.measured_length_mm = h.length_mm;
    out.length_deviation_mm = h.length_deviation_mm;
    out.length_tolerance = c.length_tolerance;
    out.form_mm = h.form_mm;
    out.arc_coverage_deg = h.arc_coverage_deg;
    out.pixel_pitch_mm = h.pixel_pitch_mm;
  }
  return out;
}

ReportDefect ReportDefectOf(const Defect& d) {
  ReportDefect out;
  out.id = d.id;
  out.kind = DefectKindName(d.kind);
  out.centroid_mm = d.centroid_mm;
  out.area_mm2 = d.area_mm2;
  out.extent_mm = d.extent_mm;
  out.peak_mm = d.peak_mm;
  out.peak_source = d.peak_fitted ? "fit" : "median";
  out.measured_extreme_mm = d.measured_extreme_mm;
  out.noise_mm = d.noise_mm;
  out.points = d.points;
  out.region = d.region;
  return out;
}

}  // namespace surfinspect
