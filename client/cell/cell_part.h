// The cell's part as the mesh the pipeline measures against. A mesh file
// (STL, OBJ, PLY, OFF) is used as it is. A STEP or IGES file is tessellated
// once by the CAD worker under the cell's "cad" settings and kept in the CAD
// cache (core/cad/cad_import.h): the second part of a run, and the next
// agent start, read the cached mesh.
#pragma once

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "client/cell/cell_config.h"
#include "core/pipeline/inspection_report.h"

namespace surfinspect::client {

// For a STEP/IGES part: tessellates it (or takes the cache), points
// cell->part_mesh at the cached OBJ (plans read the groups face:N, body:...
// from it) and sets cell->part_cad. `log` gets one line saying which. A mesh
// part is left as it is. Errors name the file; the cell is unchanged then.
absl::Status LoadCellPart(CellConfig* cell, std::string* log);

// The part mesh (cell.part_mesh, after LoadCellPart) in millimetres, scaled
// from cell.part_units.
absl::StatusOr<TriangleMesh> ReadCellPartMesh(const CellConfig& cell);

// One scan of the cell in millimetres, scaled from cell.sensor_units. When
// that unit was not stated, `doubts` gets what the plausibility rules
// (core/io/unit_doubt.h) say of the scan, and of it against `part` (null:
// the size rule only).
absl::StatusOr<PointCloud> ReadCellScan(const CellConfig& cell, const std::string& path,
                                        const TriangleMesh* part, std::vector<std::string>* doubts);

// What report.json records of the cell's units, with the doubts found.
ReportInputUnits CellInputUnits(const CellConfig& cell, std::vector<std::string> doubts);

// One line for people: "part.step: tessellated (STEP, declared MILLIMETRE, 16 faces,
// 1260 triangles, measured error 0.0050 mm <= 0.01 mm) in 0.1 s".
std::string CadSummary(const CadReport& report, bool from_cache);

}  // namespace surfinspect::client
