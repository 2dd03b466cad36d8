// TriangleMesh: a tessellated CAD surface, float vertices in millimetres and
// uint32 vertex indices per triangle. Counter-clockwise winding (seen from
// outside the material) defines the face normal, so "above the surface" is
// the side the normal points to.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

using Triangle = std::array<uint32_t, 3>;

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;  // mm, in the mesh's own frame
  std::vector<Triangle> triangles;        // CCW vertex indices

  std::size_t num_triangles() const { return triangles.size(); }

  // Unit normals (b-a)x(c-a)/|.| per triangle; zero for a degenerate one.
  std::vector<Eigen::Vector3f> FaceNormals() const;

  // Twice the area is |(b-a)x(c-a)|; a triangle is degenerate when that is
  // below 1e-12 * (longest edge)^2, i.e. it has collapsed to a segment/point.
  bool IsDegenerate(std::size_t t) const;
  std::size_t CountDegenerate() const;

  // Rejects: no triangles, an index out of range, a non-finite vertex, or
  // every triangle degenerate. Messages name the problem.
  absl::Status Validate() const;
};

struct MeshTopology {
  std::size_t boundary_edges = 0;     // edges used by exactly one triangle
  std::size_t nonmanifold_edges = 0;  // edges used by three or more
  bool closed() const { return boundary_edges == 0 && nonmanifold_edges == 0; }
};
MeshTopology AnalyzeTopology(const TriangleMesh& mesh);

// Each triangle's three undirected edges (lower vertex << 32 | upper vertex)
// sorted by edge, then triangle: a run of equal edges is the triangles that
// share it. O(n log n), no hash map.
struct EdgeUse {
  uint64_t edge = 0;
  uint32_t triangle = 0;
};
std::vector<EdgeUse> SortedEdgeUses(const TriangleMesh& mesh);

Bounds3 ComputeBounds(const TriangleMesh& mesh);

}  // namespace surfinspect
