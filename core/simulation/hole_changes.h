// A part as made from its CAD, with holes that are off: each hole the CAD
// lists (core/plan/cad_holes.h) can be moved in its plane and grown in
// size, by moving its edge's vertices, so any CAD with boundary-loop holes
// (the demo's part.stl, a customer's mesh) becomes a manufactured part with
// a known truth. The faces around the hole stretch by the shift; the moves
// must stay well inside the triangles around the edge (tenths of a mm).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "absl/status/statusor.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

struct HoleChange {
  std::size_t hole = 0;                                // index into ListHoles(cad)
  Eigen::Vector3d shift_mm = Eigen::Vector3d::Zero();  // its part along the hole's axis is dropped
  double resize_mm = 0;  // added to the diameter (a slot's width and length)
};

// InvalidArgument for a hole index the CAD does not have.
absl::StatusOr<TriangleMesh> ChangeHoles(const TriangleMesh& cad,
                                         const std::vector<HoleChange>& changes);

}  // namespace surfinspect
