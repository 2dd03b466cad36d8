// Strict checks of STL and OBJ bytes before Assimp imports them, so that
// what Assimp sees is well formed and bounded:
//  - STL: a binary file must be exactly 84 + 50 * n bytes for its declared
//    n triangles; otherwise it must be ASCII (starting with "solid"), with
//    every facet "facet normal nx ny nz / outer loop / 3 x vertex x y z /
//    endloop / endfacet" and every number a number. A facet with other than
//    3 vertices is refused, never triangulated.
//  - OBJ: every statement is one of v vt vn vp f l p g o s mtllib usemtl
//    (free-form curves and the rest are refused); v/vt/vn/vp lines hold
//    numbers; every f, l and p index is non-zero and within the vertices
//    (texture coordinates, normals) declared in the file, a negative one
//    within those declared before it; a face has 3 to 1000 corners.
// Both count facets or faces against the triangle limit. Messages start
// "cannot import:" and name the line or facet.
#pragma once

#include <string_view>

#include "absl/status/status.h"
#include "core/io/read_limits.h"

namespace surfinspect {

absl::Status CheckStl(std::string_view bytes, const MeshReadLimits& limits = {},
                      std::string_view name = "<stl>");
absl::Status CheckObj(std::string_view bytes, const MeshReadLimits& limits = {},
                      std::string_view name = "<obj>");

}  // namespace surfinspect
