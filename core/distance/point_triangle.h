// The exact closest point on a triangle to a point, in double precision,
// and which feature of the triangle it lies on (the face interior, one of
// the three edges or one of the three vertices).
//
// Algorithm: Ericson, Real-Time Collision Detection (2005), §5.1.5, the
// Voronoi-region method. The feature is what the signed distance needs: the
// sign is taken from the angle-weighted pseudonormal of that feature
// (Bærentzen & Aanæs 2005), see core/distance/mesh_index.h. Pure math, no BVH types.
#pragma once

#include <Eigen/Core>
#include <cstdint>

namespace surfinspect {

// Edges are named by the triangle's vertex order: AB = (v0, v1),
// BC = (v1, v2), CA = (v2, v0).
enum class ClosestFeature : uint8_t {
  kFace,
  kEdgeAB,
  kEdgeBC,
  kEdgeCA,
  kVertexA,
  kVertexB,
  kVertexC
};

struct PointTriangleResult {
  Eigen::Vector3d point;  // the closest point on the triangle, same frame as the inputs
  ClosestFeature feature = ClosestFeature::kFace;
  double squared_distance = 0;  // |p - point|^2, mm^2 when the inputs are in mm
};

// How the kernel answers a triangle: by Ericson's regions, as a sliver, or
// as three segments. A mesh index classifies each triangle once.
enum class TriangleShape : uint8_t { kRegular, kSliver, kDegenerate };
TriangleShape ClassifyTriangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                               const Eigen::Vector3d& c);

// Exact for any finite input. A sliver (twice the area <= 1e-3 times the
// longest edge squared) is answered by projection and segments instead of
// Ericson's dot-product regions, which lose their precision there. A degenerate triangle (collapsed
// to a segment or a point, same test as TriangleMesh::IsDegenerate) has no face region: the answer
// is then the closest of its three edges taken as segments, and the feature is an edge or a vertex.
PointTriangleResult ClosestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                           const Eigen::Vector3d& b, const Eigen::Vector3d& c);
// The same with the shape known: `shape` must be ClassifyTriangle(a, b, c).
PointTriangleResult ClosestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                           const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                           TriangleShape shape);

// Inline: every query's sign asks them.
inline bool IsEdge(ClosestFeature f) {
  return f == ClosestFeature::kEdgeAB || f == ClosestFeature::kEdgeBC ||
         f == ClosestFeature::kEdgeCA;
}
inline bool IsVertex(ClosestFeature f) {
  return f == ClosestFeature::kVertexA || f == ClosestFeature::kVertexB ||
         f == ClosestFeature::kVertexC;
}
// Index 0..2 of the edge's first vertex (AB -> 0, BC -> 1, CA -> 2) or of the
// vertex (A -> 0, ...); -1 for kFace.
inline int FeatureIndex(ClosestFeature f) {
  if (IsEdge(f)) return static_cast<int>(f) - static_cast<int>(ClosestFeature::kEdgeAB);
  if (IsVertex(f)) return static_cast<int>(f) - static_cast<int>(ClosestFeature::kVertexA);
  return -1;
}

}  // namespace surfinspect
