#include "client/cell/cell_part.h"

#include "absl/strings/str_format.h"
#include "core/cad/cad_import.h"

namespace surfinspect::client {

std::string CadSummary(const CadReport& r, bool from_cache) {
  std::string s = absl::StrFormat(
      "%s: %s (%s, declared unit %s, %zu faces, %zu triangles, measured tessellation error "
      "%.4f mm %s %g mm)",
      r.source, from_cache ? "cached tessellation reused" : "tessellated", r.format,
      r.declared_unit.empty() ? "unknown" : r.declared_unit, r.faces, r.triangles,
      r.tessellation_error_mm, r.tolerance_held ? "<=" : "EXCEEDS", r.chord_tolerance_mm);
  if (!from_cache) absl::StrAppendFormat(&s, " in %.2f s, %d pass(es)", r.seconds, r.passes);
  return s;
}

absl::Status LoadCellPart(CellConfig* cell, std::string* log) {
  if (!IsCadPath(cell->part_source)) return absl::OkStatus();
  absl::StatusOr<CadMesh> cad = ImportCad(cell->part_source, cell->cad, cell->cad_cache);
  if (!cad.ok()) return cad.status();
  cell->part_mesh = cad->mesh_path;
  cell->part_cad = cad->report;
  if (log) *log = CadSummary(cad->report, cad->from_cache);
  return absl::OkStatus();
}

}  // namespace surfinspect::client
