// Mesh files: STL (ascii and binary), OBJ, PLY and OFF are read; STL, OBJ
// and PLY are written, through Assimp. PLY and OFF are read by our own
// parsers (ply_mesh.h, off_format.h); STL and OBJ by Assimp after a strict
// check of the bytes (mesh_precheck.h). On read, per-vertex attributes are
// dropped and identical vertex positions merged, so an STL (which stores
// three vertices per facet) comes back with shared vertices and its
// topology (closed or open) can be analysed. Every path gives the mesh the
// Assimp import gave.
#pragma once

#include <string>

#include "absl/status/statusor.h"
#include "core/io/length_units.h"
#include "core/io/read_limits.h"
#include "core/types/mesh_groups.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

// Fails with a message naming the file for: unreadable or truncated files,
// no triangles, non-finite vertices, only degenerate triangles, limits.
absl::StatusOr<TriangleMesh> ReadMesh(const std::string& path, const MeshReadLimits& limits = {});

// The named groups of the file ReadMesh read as `mesh`: an OBJ's `g` / `o`
// groups (obj_groups.h); empty for other formats and files without groups.
// `mesh` may have been scaled to millimetres from the file's `file_unit`.
// FailedPrecondition when the groups cannot be mapped onto the triangles.
absl::StatusOr<MeshGroups> ReadMeshGroups(const std::string& path, const TriangleMesh& mesh,
                                          const MeshReadLimits& limits = {},
                                          LengthUnit file_unit = LengthUnit::kMillimetre);

// True when the file's PLY header parses and declares a face element with
// rows: such a PLY is a mesh, any other a point cloud.
bool PlyDeclaresFaces(const std::string& path);

enum class MeshFormat { kStlBinary, kStlAscii, kObj, kPlyBinary, kPlyAscii };

// Format from the extension when omitted (.stl binary, .obj, .ply binary).
// Written atomically.
absl::Status WriteMesh(const std::string& path, const TriangleMesh& mesh);
absl::Status WriteMesh(const std::string& path, const TriangleMesh& mesh, MeshFormat format);

}  // namespace surfinspect
