// The `g` / `o` groups of an OBJ file, mapped onto the triangles that
// ReadMesh gave for the same file. The geometry stays Assimp's (io_mesh.h);
// this reader walks the file's faces in order (each face of n corners gives
// n - 2 triangles) and checks, triangle by triangle, that every corner of the
// imported triangle is a corner of the file's face it is mapped to. An
// importer that reordered faces (Assimp splits an object by material) is
// caught by that check and refused with a message, never mapped wrongly.
#pragma once

#include <string_view>

#include "absl/status/statusor.h"
#include "core/io/length_units.h"
#include "core/types/mesh_groups.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

// `bytes` passed CheckObj (mesh_precheck.h); `imported` is ReadMesh's mesh of
// the same bytes, possibly scaled to millimetres from `file_unit`
// (length_units.h). Empty groups when the file names none.
absl::StatusOr<MeshGroups> ObjGroups(std::string_view bytes, const TriangleMesh& imported,
                                     std::string_view name = "<obj>",
                                     LengthUnit file_unit = LengthUnit::kMillimetre);

// The OBJ text of `mesh` with its groups: a `g` line before each run of
// triangles in the same groups, vertices with 9 significant digits (every
// float comes back exact). Names must not hold blanks (InvalidArgument).
absl::StatusOr<std::string> ObjWithGroups(const TriangleMesh& mesh, const MeshGroups& groups);

}  // namespace surfinspect
