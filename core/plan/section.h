// Sections: a plane through the part, as on a drawing's section view. The
// nominal curve is the CAD mesh cut by the plane (each triangle that the
// plane crosses gives a segment; segments sharing a mesh edge are chained
// into polylines). The measured side is every matched point whose closest
// CAD point lies within +-width/2 of the plane (selected like regions and
// comparison points, by the closest point, so a section reads the same
// points whatever the scan's frame), with the min/max/mean of their signed
// deviations and whiskers for the reports: at a point's closest CAD point,
// its deviation drawn along the curve's normal in the plane (the CAD face
// normal with its out-of-plane part removed).
//
// Units mm, part frame; deviations signed (+ above the CAD surface).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "core/errormap/error_map.h"
#include "core/plan/triangle_points.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

struct SectionPlane {
  Eigen::Vector3d point_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();  // unit
  double width_mm = 1.0;                              // the slab of measured points, > 0
};

struct SectionWhisker {
  Eigen::Vector3d at_mm = Eigen::Vector3d::Zero();      // the closest CAD point
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // unit, in the plane
  float deviation_mm = 0;
};

struct SectionCut {
  SectionPlane plane;  // as cut (unit normal)
  // The nominal curve: polylines of at least two vertices, each vertex on
  // a mesh edge (or vertex) in the plane.
  std::vector<std::vector<Eigen::Vector3d>> polylines;
  std::size_t segments = 0;                          // triangles crossed
  std::vector<uint32_t> points;                      // error-map indices in the slab, ascending
  double min_mm = NAN, max_mm = NAN, mean_mm = NAN;  // over those points
  std::vector<SectionWhisker> whiskers;              // up to max_whiskers, evenly over `points`
  double coverage = NAN;  // of the curve's length seen (SectionCoverage); NaN when not computed
};

inline constexpr std::size_t kDefaultMaxWhiskers = 400;

// `triangles`, when not empty, limits the cut and the points to those CAD
// triangles (a section limited to a region): 1 selects. `by_triangle`,
// when given, is PointsByTriangle of the same map and part: only the
// triangles near the slab are read (the same points as without it).
// InvalidArgument for a zero normal, a width <= 0, or sizes that do not
// match the part.
absl::StatusOr<SectionCut> CutSection(const TriangleMesh& part, const ErrorMapResult& error_map,
                                      const SectionPlane& plane,
                                      const std::vector<uint8_t>& triangles = {},
                                      std::size_t max_whiskers = kDefaultMaxWhiskers,
                                      const TrianglePoints* by_triangle = nullptr);

// The fraction of the nominal curve's length that has a point of the slab
// (its closest CAD point, as everywhere in coverage: core/plan/coverage.h)
// within distance_mm: the curve sampled every distance_mm / 2, each sample
// weighing its piece. 0 for a cut without a curve.
double SectionCoverage(const SectionCut& cut, const ErrorMapResult& error_map, double distance_mm);

}  // namespace surfinspect
