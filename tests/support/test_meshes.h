// Procedural meshes and brute-force oracles shared by the mesh-index and
// error-map tests. All meshes are in mm with CCW (outward / upward) faces.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>

#include "core/distance/mesh_index.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect::testing {

// Closed meshes.
TriangleMesh Icosphere(double radius, int subdivisions);
TriangleMesh Torus(double major_radius, double minor_radius, int major_segments,
                   int minor_segments);
TriangleMesh Box(const Eigen::Vector3d& min, const Eigen::Vector3d& max);

// An open height field z = f(x, y) over [x0, x1] x [y0, y1] on an nx x ny
// vertex grid, normals up (+z). Each cell is split along its (i,j)-(i+1,j+1)
// diagonal.
TriangleMesh HeightField(double x0, double x1, double y0, double y1, int nx, int ny,
                         const std::function<double(double, double)>& f);

// The plane z = 0 over [0, 100]^2 mm on an 11 x 11 grid, normals up.
TriangleMesh FlatSquare();

// The mesh's index; a failed build fails the test and gives null.
std::unique_ptr<MeshIndex> IndexOf(const TriangleMesh& mesh);

// Generalised winding number of a closed mesh at p (sum of the triangles'
// signed solid angles / 4 pi; Van Oosterom & Strackee 1983): ~1 inside,
// ~0 outside for outward faces.
double WindingNumber(const TriangleMesh& mesh, const Eigen::Vector3d& p);

// Point-triangle distance by projection onto the plane (kept if the
// barycentric coordinates are >= 0) or else the best clamped edge segment:
// an oracle that shares no code with Ericson's region method.
double DistanceByProjection(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& b, const Eigen::Vector3d& c);

// The z of a height-field mesh above (x, y), found by brute force over all
// triangles in projection; NaN when no triangle covers (x, y).
double MeshHeightAt(const TriangleMesh& mesh, double x, double y);

}  // namespace surfinspect::testing
