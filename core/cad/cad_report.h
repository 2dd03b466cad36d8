// What a tessellation of a STEP or IGES file was, and how far its triangles
// are from the exact surfaces: written beside every mesh `surfinspect cad`
// makes, kept in the CAD cache, and carried (as its summary) by every report
// made against such a mesh, so a deviation can be read against the error
// the mesh itself brings (docs/cad.md).
//
// tessellation_error_mm is measured, not OCCT's target: on each face, points
// of the exact surface at barycentric samples of every triangle's UV
// coordinates, against the same samples of the flat triangle, and points of
// each boundary edge's exact curve against the polyline that replaced it.
// The largest such distance over all faces bounds, at those samples, both
// the distance from the surface to the mesh and from the mesh to the surface.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

struct CadReport {
  std::string source;         // the file's name, as given
  std::string source_sha256;  // of its bytes: the cache key's root
  std::string format;         // "STEP" or "IGES"
  std::string declared_unit;  // the file's length unit ("MM", "INCH", "M", ...)
  std::string output_unit = "mm";
  std::vector<std::string> bodies;  // every body (product) in the file
  std::string body;                 // the one chosen with --body, "" for all
  std::size_t faces = 0, triangles = 0;
  double chord_tolerance_mm = 0;
  double angular_tolerance_deg = 0;
  double deflection_mm = 0;          // OCCT's deflection on the last pass
  int passes = 0;                    // meshing passes (1 + refinements)
  double tessellation_error_mm = 0;  // measured, the largest over faces
  bool tolerance_held = false;       // tessellation_error_mm <= chord_tolerance_mm
  // The file's largest edge tolerance (its curves' gap to their surfaces):
  // when the measured error stalls near it, finer meshing cannot help.
  double brep_tolerance_mm = 0;
  std::vector<double> face_error_mm;  // per face, in the order of the groups face:1..
  Bounds3 bounds_mm;                  // of the mesh
  double seconds = 0;                 // read, mesh and measure
};

nlohmann::json EncodeCadReport(const CadReport& report);
// DataLoss naming the field for a value of the wrong type.
absl::StatusOr<CadReport> DecodeCadReport(const nlohmann::json& json);

}  // namespace surfinspect
