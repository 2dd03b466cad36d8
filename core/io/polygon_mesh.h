// Triangles from an indexed polygon list (the faces of a PLY or OFF file),
// built the way the Assimp import of these files built them (Triangulate,
// then JoinIdenticalVertices), so that a file gives the same mesh whichever
// path read it:
//  - a quad is split into two triangles fanned from its concave corner if
//    it has one (the corner whose two angles to the diagonal sum above pi),
//    else from its first corner;
//  - in a mesh with quads, a triangle whose first corner equals the
//    previous face's is rotated one step (Assimp's n-gon encoding);
//  - unreferenced vertices are dropped, vertices with equal coordinates
//    (==, so -0 equals 0) are merged into the first in file order, and the
//    remaining vertices keep file order.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

struct IndexedPolygons {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<uint32_t> corners;  // vertex indices, face after face
  std::vector<uint8_t> sizes;     // corners per face: 3 or 4
};

// Fails when a corner index is out of range or a face is not a triangle or
// a quad (the parsers refuse those first, with the face's number).
absl::StatusOr<TriangleMesh> TriangulateAndMerge(const IndexedPolygons& polygons,
                                                 std::string_view name);

// A vertex coordinate token parsed as Assimp's ascii importers parse it
// (fast_atoreal_move, which is not always correctly rounded), after a
// strict check that the token is a decimal number. T is float or double.
bool ParseMeshCoordinate(std::string_view token, float* out);
bool ParseMeshCoordinate(std::string_view token, double* out);

}  // namespace surfinspect
