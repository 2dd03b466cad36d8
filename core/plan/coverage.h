// Coverage: how much of the CAD surface the scan saw. A location on the CAD
// surface is covered when a matched point's closest CAD point lies within
// distance_mm of it; the coverage of an area is the covered fraction of it.
// Without it a region that the sensor barely saw (a shadow, a missing
// viewpoint) would be judged, and pass, on a handful of points.
//
// The area is sampled on a square grid of sample_mm cells in each CAD
// triangle's plane; the cells whose centres lie inside the triangle stand
// for equal parts of its area (a triangle smaller than a cell, by its
// centroid). A sample is covered by the matched closest points on its
// triangle and those on the triangles sharing its edges that lie within
// distance_mm of the shared edge, so coverage runs across an edge as on the
// surface (not across a vertex-only neighbour: a scanned area ending
// exactly at such a corner loses a sliver < distance_mm).
// Per triangle, region (ResolvedInspectionPlan's rows) and the whole
// surface; a comparison point's coverage is that of the part of the surface
// within its radius. Units mm, part frame. Deterministic for any thread count.
#pragma once

#include <atomic>
#include <cstddef>
#include <vector>

#include "absl/status/statusor.h"
#include "core/errormap/error_map.h"
#include "core/plan/inspection_plan.h"
#include "core/plan/triangle_points.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

struct CoverageSettings {
  double distance_mm = 1.0;  // a location this close to a measured point is covered; > 0
  double sample_mm = 0;      // sampling cell size; 0 = distance_mm / 2
  int threads = 0;           // 0 = all cores
};

struct CoverageResult {
  double distance_mm = 0, sample_mm = 0;  // used
  double surface = 0;                     // covered fraction of the whole CAD area
  std::vector<double> regions;            // per plan region, plan order; 0 for an empty region
  std::vector<double> points;             // per comparison point: of the area within its radius
  std::vector<float> triangles;           // per CAD triangle, for the reports' pictures
};

// `error_map` was computed against `part`; `plan` was resolved on `part`;
// `by_triangle`, when given, is PointsByTriangle of the same map and part
// (built here otherwise). InvalidArgument for bad settings or mismatched
// sizes; Cancelled when `cancel` is raised (polled per block of triangles).
absl::StatusOr<CoverageResult> ComputeCoverage(const ErrorMapResult& error_map,
                                               const TriangleMesh& part,
                                               const ResolvedInspectionPlan& plan,
                                               const CoverageSettings& settings,
                                               const std::atomic<bool>* cancel = nullptr,
                                               const TrianglePoints* by_triangle = nullptr);

}  // namespace surfinspect
