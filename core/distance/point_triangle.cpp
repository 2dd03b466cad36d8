#include "core/distance/point_triangle.h"

#include <Eigen/Geometry>
#include <algorithm>

namespace surfinspect {
namespace {

PointTriangleResult Make(const Eigen::Vector3d& p, const Eigen::Vector3d& q, ClosestFeature f) {
  return PointTriangleResult{q, f, (p - q).squaredNorm()};
}

// Closest point on the segment [a, b]; a zero-length segment is vertex a.
PointTriangleResult ClosestOnSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                     const Eigen::Vector3d& b, ClosestFeature edge,
                                     ClosestFeature vertex_a, ClosestFeature vertex_b) {
  const Eigen::Vector3d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? (p - a).dot(ab) / len2 : 0.0;
  if (t <= 0) return Make(p, a, vertex_a);
  if (t >= 1) return Make(p, b, vertex_b);
  return Make(p, a + t * ab, edge);
}

// Same criterion as TriangleMesh::IsDegenerate, so the mesh and the kernel
// agree on which triangles have no face.
bool Degenerate(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const double longest2 =
      std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  return longest2 == 0 || (b - a).cross(c - a).norm() <= 1e-12 * longest2;
}

// A sliver: twice the area at most kSliver times the longest edge squared.
// Ericson's region tests subtract products of dot products (va, vb, vc
// below); on a sliver they cancel, and for 2A / L^2 <= 1e-4 the test
// ClosestIsTheBruteForceMinimiserOnSlivers saw them pick the wrong region,
// off by more than the sliver's height. 1e-3 still agreed with the oracle.
constexpr double kSliver = 1e-3;

bool Sliver(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const double longest2 =
      std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  return (b - a).cross(c - a).norm() <= kSliver * longest2;
}

// For a sliver: the face projection when it falls inside by the signs of
// the sub-triangle areas about the normal (no products of dot products),
// unless an edge, taken as a segment, is at least as close.
PointTriangleResult SliverClosest(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                  const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  using F = ClosestFeature;
  PointTriangleResult best = ClosestOnSegment(p, a, b, F::kEdgeAB, F::kVertexA, F::kVertexB);
  for (const PointTriangleResult& r :
       {ClosestOnSegment(p, b, c, F::kEdgeBC, F::kVertexB, F::kVertexC),
        ClosestOnSegment(p, c, a, F::kEdgeCA, F::kVertexC, F::kVertexA)})
    if (r.squared_distance < best.squared_distance) best = r;
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const Eigen::Vector3d q = p - n * ((p - a).dot(n) / n.squaredNorm());
  const bool inside = (b - q).cross(c - q).dot(n) >= 0 && (c - q).cross(a - q).dot(n) >= 0 &&
                      (a - q).cross(b - q).dot(n) >= 0;
  if (inside && (p - q).squaredNorm() < best.squared_distance) return Make(p, q, F::kFace);
  return best;
}

}  // namespace

TriangleShape ClassifyTriangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                               const Eigen::Vector3d& c) {
  if (Degenerate(a, b, c)) return TriangleShape::kDegenerate;
  return Sliver(a, b, c) ? TriangleShape::kSliver : TriangleShape::kRegular;
}

PointTriangleResult ClosestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                           const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  return ClosestPointOnTriangle(p, a, b, c, ClassifyTriangle(a, b, c));
}

PointTriangleResult ClosestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                           const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                           TriangleShape shape) {
  using F = ClosestFeature;
  if (shape == TriangleShape::kDegenerate) {
    // No face region: the closest of the three edges as segments.
    PointTriangleResult best = ClosestOnSegment(p, a, b, F::kEdgeAB, F::kVertexA, F::kVertexB);
    for (const PointTriangleResult& r :
         {ClosestOnSegment(p, b, c, F::kEdgeBC, F::kVertexB, F::kVertexC),
          ClosestOnSegment(p, c, a, F::kEdgeCA, F::kVertexC, F::kVertexA)})
      if (r.squared_distance < best.squared_distance) best = r;
    return best;
  }
  if (shape == TriangleShape::kSliver) return SliverClosest(p, a, b, c);
  // Ericson §5.1.5: test the Voronoi regions of A, B, edge AB, C, edge CA,
  // edge BC, and finally the face, using dot products only.
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return Make(p, a, F::kVertexA);

  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return Make(p, b, F::kVertexB);

  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return Make(p, a + (d1 / (d1 - d3)) * ab, F::kEdgeAB);

  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return Make(p, c, F::kVertexC);

  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return Make(p, a + (d2 / (d2 - d6)) * ac, F::kEdgeCA);

  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return Make(p, b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b), F::kEdgeBC);

  // Inside the face: barycentric (u, v, w) = (va, vb, vc) / (va + vb + vc).
  const double denom = 1.0 / (va + vb + vc);
  return Make(p, a + ab * (vb * denom) + ac * (vc * denom), F::kFace);
}

}  // namespace surfinspect
