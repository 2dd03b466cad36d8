#include "core/simulation/hole_changes.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/plan/cad_holes.h"
#include "core/plan/profile_fit.h"

namespace surfinspect {
namespace {

// Vertices on boundary edges: the only ones an edge can be made of.
std::vector<uint8_t> BoundaryVertices(const TriangleMesh& mesh) {
  std::vector<uint8_t> on(mesh.vertices.size(), 0);
  for (const EdgeUse& use : BoundaryEdges(mesh)) {
    on[use.edge >> 32] = 1;
    on[use.edge & 0xffffffffu] = 1;
  }
  return on;
}

}  // namespace

absl::StatusOr<TriangleMesh> ChangeHoles(const TriangleMesh& cad,
                                         const std::vector<HoleChange>& changes) {
  const std::vector<CadHole> holes = ListHoles(cad);
  const std::vector<uint8_t> boundary = BoundaryVertices(cad);
  TriangleMesh made = cad;
  for (const HoleChange& c : changes) {
    if (c.hole >= holes.size())
      return absl::InvalidArgumentError(
          absl::StrCat("hole ", c.hole, ": the CAD has ", holes.size(), " holes"));
    const CadHole& h = holes[c.hole];
    if (h.rim)
      return absl::InvalidArgumentError(absl::StrCat(
          "hole ", c.hole, ": a solid's rim; only holes that are boundary loops can be changed"));
    const PlaneFrame f = MakePlaneFrame(h.position_mm, h.axis, h.direction);
    const ProfileFit contour = NominalContour(h.slot, h.diameter_mm, h.length_mm);
    const Eigen::Vector3d shift = c.shift_mm - c.shift_mm.dot(f.axis) * f.axis;
    const double tol = std::max(0.01, 0.02 * contour.radius);
    for (std::size_t v = 0; v < cad.vertices.size(); ++v) {
      const Eigen::Vector3d p = cad.vertices[v].cast<double>();
      const Eigen::Vector2d q = f.To2d(p);
      if (!boundary[v] || std::abs((p - f.origin).dot(f.axis)) > tol ||
          std::abs(ProfileDistance(contour, q)) > tol)
        continue;
      // Out from the centre segment: radial at the ends, across the sides.
      const double u = std::clamp(q.x(), -contour.half_length, contour.half_length);
      const Eigen::Vector2d out = (q - Eigen::Vector2d(u, 0)).normalized();
      const Eigen::Vector3d grow = 0.5 * c.resize_mm * (out.x() * f.e1 + out.y() * f.e2);
      made.vertices[v] = (p + shift + grow).cast<float>();
    }
  }
  return made;
}

}  // namespace surfinspect
