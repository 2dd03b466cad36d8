// A STEP or IGES file to a mesh in millimetres whose measured tessellation
// error holds the chosen chord tolerance (docs/cad.md): read with XCAF
// (occt_model.h), meshed with BRepMesh_IncrementalMesh, measured face by
// face (face_error.h), and meshed again finer while the measured error
// exceeds the tolerance: OCCT's deflection is a target, not a bound (at a
// 0.01 mm deflection real parts measured 0.014-0.048 mm).
//
// Runs OpenCASCADE on the file's bytes: call it only in the short-lived
// child process (client/cad/cad_worker.cpp), never in a server or agent.
#pragma once

#include <TopoDS_Shape.hxx>
#include <string>

#include "absl/status/statusor.h"
#include "core/cad/cad_report.h"
#include "core/cad/cad_settings.h"
#include "core/types/mesh_groups.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect::occt {

struct CadTessellation {
  TriangleMesh mesh;  // faces one after the other, each with its own vertices
  // Each triangle is in face:N (N from 1, the file's face order) and, where
  // the file says, name:NAME, color:#rrggbb and body:NAME.
  MeshGroups groups;
  CadReport report;
};

// One meshing of `shape` as every pass does it: BRepMesh_IncrementalMesh at
// `deflection_mm` and `angle_deg`, faces in parallel, Delabella's Delaunay.
void MeshShape(const TopoDS_Shape& shape, double deflection_mm, double angle_deg);

// The report's `passes` says how many meshings it took; tolerance_held is
// false (with the measured error) when kMaxPasses did not reach it.
absl::StatusOr<CadTessellation> TessellateCad(const std::string& path,
                                              const TessellationSettings& settings);

}  // namespace surfinspect::occt
