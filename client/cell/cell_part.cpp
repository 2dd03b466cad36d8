#include "client/cell/cell_part.h"

#include <algorithm>
#include <optional>

#include "absl/strings/str_format.h"
#include "core/cad/cad_import.h"
#include "core/io/io_mesh.h"
#include "core/io/io_point_cloud.h"
#include "core/io/unit_doubt.h"

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

absl::StatusOr<TriangleMesh> ReadCellPartMesh(const CellConfig& cell) {
  absl::StatusOr<TriangleMesh> mesh = ReadMesh(cell.part_mesh);
  if (mesh.ok()) ScaleToMillimetres(cell.part_units.unit, &*mesh);
  return mesh;
}

absl::StatusOr<PointCloud> ReadCellScan(const CellConfig& cell, const std::string& path,
                                        const TriangleMesh* part,
                                        std::vector<std::string>* doubts) {
  absl::StatusOr<PointCloud> cloud = ReadPointCloud(path);
  if (!cloud.ok()) return cloud;
  ScaleToMillimetres(cell.sensor_units.unit, &*cloud);
  if (cell.sensor_units.stated && cell.part_units.stated) return cloud;
  const UnitSubject scan{"scan " + path, "cell.json's sensor.units =", ExtentOf(*cloud),
                         cell.sensor_units.stated};
  std::optional<UnitSubject> mesh;
  if (part)
    mesh = UnitSubject{"part " + cell.part_mesh, "cell.json's part.units =", ExtentOf(*part),
                       cell.part_units.stated};
  for (std::string& d : UnitDoubts(scan, mesh ? &*mesh : nullptr))
    if (std::find(doubts->begin(), doubts->end(), d) == doubts->end()) doubts->push_back(d);
  return cloud;
}

ReportInputUnits CellInputUnits(const CellConfig& cell, std::vector<std::string> doubts) {
  return {LengthUnitName(cell.sensor_units.unit), LengthUnitName(cell.part_units.unit),
          cell.sensor_units.stated, cell.part_units.stated, std::move(doubts)};
}

}  // namespace surfinspect::client
