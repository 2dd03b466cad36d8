// A triangle mesh from PLY bytes (ply_format.h does the parsing): the vertex
// element's x, y and z (any numeric type) and the face element's
// vertex_indices (or vertex_index) lists. Triangles and quads are read (see
// polygon_mesh.h for how quads are split and vertices merged); a face with
// fewer than 3 or more than 4 corners, or an index out of range, is refused
// with the face's number.
#pragma once

#include <string_view>

#include "absl/status/statusor.h"
#include "core/io/read_limits.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

absl::StatusOr<TriangleMesh> ParsePlyMesh(std::string_view bytes, const MeshReadLimits& limits = {},
                                          std::string_view name = "<ply>");

}  // namespace surfinspect
