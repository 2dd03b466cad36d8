// Strict checks of STL and OBJ bytes before Assimp imports them, so that
// what Assimp sees is well formed and bounded:
//  - STL: a binary file must be exactly 84 + 50 * n bytes for its declared
//    n triangles; otherwise it must be ASCII (starting with "solid"), with
//    every facet "facet normal nx ny nz / outer loop / 3 x vertex x y z /
//    endloop / endfacet" and every number a number. Keywords match in any
//    case, as other readers accept them. A facet with other than 3 vertices
//    is refused, never triangulated. A file that starts with "solid" and is
//    neither is refused with both readings' reasons (the header of a
//    binary STL may start with "solid").
//  - OBJ: every statement is one of v vt vn vp f l p g o s mtllib usemtl
//    (free-form curves and the rest are refused); v/vt/vn/vp lines hold
//    numbers; every f, l and p index is non-zero and within the vertices
//    (texture coordinates, normals) declared in the file, a negative one
//    within those declared before it; a face has 3 to 1000 corners.
// Both count facets or faces against the triangle limit. Messages start
// "cannot import:" and name the line or facet.
#pragma once

#include <string>
#include <string_view>

#include "absl/status/status.h"
#include "core/io/read_limits.h"

namespace surfinspect {

absl::Status CheckStl(std::string_view bytes, const MeshReadLimits& limits = {},
                      std::string_view name = "<stl>");
// CheckStl, and then the bytes made ready for Assimp 5.2, whose STL reader
// matches keywords case-sensitively (it reads "FACET NORMAL" as no facet at
// all, silently): an ASCII STL's keywords are lower-cased in place, and
// nothing else (the solids' names, the numbers) is changed.
absl::Status CheckStlForAssimp(std::string* bytes, const MeshReadLimits& limits = {},
                               std::string_view name = "<stl>");
absl::Status CheckObj(std::string_view bytes, const MeshReadLimits& limits = {},
                      std::string_view name = "<obj>");

}  // namespace surfinspect
