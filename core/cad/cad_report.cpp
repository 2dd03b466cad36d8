#include "core/cad/cad_report.h"

#include "core/types/json_fields.h"

namespace surfinspect {
namespace {

template <typename V, typename R>
void VisitCadReport(V& v, R& r) {
  v("source", r.source);
  v("source_sha256", r.source_sha256);
  v("format", r.format);
  v("declared_unit", r.declared_unit);
  v("output_unit", r.output_unit);
  v("bodies", r.bodies);
  v("body", r.body);
  v("faces", r.faces);
  v("triangles", r.triangles);
  v("chord_tolerance_mm", r.chord_tolerance_mm);
  v("angular_tolerance_deg", r.angular_tolerance_deg);
  v("deflection_mm", r.deflection_mm);
  v("passes", r.passes);
  v("tessellation_error_mm", r.tessellation_error_mm);
  v("tolerance_held", r.tolerance_held);
  v("brep_tolerance_mm", r.brep_tolerance_mm);
  v("bounds_min_mm", r.bounds_mm.min);
  v("bounds_max_mm", r.bounds_mm.max);
  v("seconds", r.seconds);
  v("face_error_mm", r.face_error_mm);
}

}  // namespace

nlohmann::json EncodeCadReport(const CadReport& report) {
  JsonWriter w;
  VisitCadReport(w, report);
  return std::move(w.out);
}

absl::StatusOr<CadReport> DecodeCadReport(const nlohmann::json& json) {
  CadReport report;
  JsonReader r(json, "cad");
  VisitCadReport(r, report);
  if (!r.status().ok()) return r.status();
  return report;
}

}  // namespace surfinspect
