// A triangle mesh from OFF bytes (Object File Format), parsed by our own
// code: the keyword line (OFF, with the optional ST, C and N prefixes of
// texture, colour and normal data, which are read past), the vertex, face
// and edge counts, then one vertex and one face per line. The counts are
// checked against the limits and against what the remaining bytes can hold
// (a vertex line takes at least 6 bytes, a face line at least 2) before
// anything is allocated. Triangles and quads are read (polygon_mesh.h);
// a face with fewer than 3 or more than 4 corners, or an index out of range,
// is refused with the face's number. '#' starts a comment.
#pragma once

#include <string_view>

#include "absl/status/statusor.h"
#include "core/io/read_limits.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

absl::StatusOr<TriangleMesh> ParseOff(std::string_view bytes, const MeshReadLimits& limits = {},
                                      std::string_view name = "<off>");

}  // namespace surfinspect
