// The holes and slots of a CAD mesh, as a plan is written from them: each
// boundary loop of the mesh (a chain of edges used by one triangle) that is
// planar and whose vertices lie on a circle, or on a slot (a stadium), is a
// hole. The outer boundary and irregular cut-outs fit neither and are left
// out. A solid (a STEP part tessellated, a closed mesh) has no boundary:
// its hole is a cylinder wall, found by its rims, the loops of sharp edges
// (> 60 degrees) where a face meets a wall that faces the axis, each
// listed with the axis its face looks to (both ends of a through hole; a
// boss, whose wall faces away, is not a hole). A rim rounded by a fillet
// has no sharp edge and is not found (docs/inspection-plan.md#holes-and-slots).
//
// Units mm, part frame. NearestBoundaryEdge gives the trim edge at a point.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <vector>

#include "core/types/triangle_mesh.h"

namespace surfinspect {

// A plane's 2D frame: origin, unit axis (its normal) and an in-plane basis
// (e1, e2, axis) right-handed. For a slot e1 runs along its length.
struct PlaneFrame {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d e1 = Eigen::Vector3d::UnitX(), e2 = Eigen::Vector3d::UnitY();
  Eigen::Vector2d To2d(const Eigen::Vector3d& p) const {
    return {(p - origin).dot(e1), (p - origin).dot(e2)};
  }
  Eigen::Vector3d To3d(const Eigen::Vector2d& q) const { return origin + q.x() * e1 + q.y() * e2; }
};
// The frame about `axis` (need not be unit); e1 is `along` made normal to
// the axis when given and not parallel to it, else a fixed choice: the
// world axis least aligned with `axis`, made normal to it.
PlaneFrame MakePlaneFrame(const Eigen::Vector3d& origin, const Eigen::Vector3d& axis,
                          const Eigen::Vector3d& along = Eigen::Vector3d::Zero());

struct CadHole {
  bool slot = false;
  Eigen::Vector3d position_mm = Eigen::Vector3d::Zero();  // the centre, in the loop's plane
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();        // unit; the side the faces around it face
  double diameter_mm = 0;                                 // a slot's width
  double length_mm = 0;                                   // a slot's overall length; 0 for a circle
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();    // a slot's length direction (unit)
  double form_mm = 0;      // the loop's vertices about the fitted contour, max - min
  double flatness_mm = 0;  // the loop's vertices about its plane, max - min
  std::size_t vertices = 0;
  bool rim = false;  // a solid's rim (sharp edges), not a boundary loop
};

struct CadHoleSettings {
  double max_size_mm = 100;          // larger loops are not holes (the outer boundary)
  double max_form_ratio = 0.01;      // form / diameter at most this (a tessellated circle: ~0)
  double max_flatness_ratio = 0.05;  // flatness / size at most this
};

// The mesh's boundary: its edges used by one triangle (SortedEdgeUses's
// runs of one), with that triangle.
std::vector<EdgeUse> BoundaryEdges(const TriangleMesh& mesh);

// Sorted by position (x, then y, then z) so the list reads the same for the
// same mesh.
std::vector<CadHole> ListHoles(const TriangleMesh& mesh, const CadHoleSettings& settings = {});

// The CAD's boundary (a trim edge) at a point: the nearest boundary edge
// (used by one triangle), the point on it, its direction, its triangle's
// normal and the direction in that triangle's plane off the material.
struct CadEdge {
  Eigen::Vector3d point_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d tangent = Eigen::Vector3d::UnitX(), normal = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d outward = Eigen::Vector3d::UnitY();
  double distance_mm = 0;  // from the point asked about
};
// None for a closed mesh (no boundary).
std::optional<CadEdge> NearestBoundaryEdge(const TriangleMesh& mesh, const Eigen::Vector3d& p);

}  // namespace surfinspect
