// Coverage: how much of the CAD surface the scan saw. A location on the CAD
// surface is covered when a matched point's closest CAD point lies within
// distance_mm of it; the coverage of an area is the covered fraction of it.
// Without it a region that the sensor barely saw (a shadow, a missing
// viewpoint) would be judged, and pass, on a handful of points.
//
// The area is sampled exactly: each CAD triangle is cut into n x n congruent
// sub-triangles (n = ceil(longest edge / sample_mm)), each standing for its
// area at its centroid, so a fraction is area-weighted. The closest points
// sit in a hash grid of cells distance_mm wide; a centroid looks at its 27
// cells. Per triangle, region (ResolvedInspectionPlan's rows) and the whole
// surface; a comparison point's coverage is that of the part of the surface
// within its radius. Units mm, part frame. Deterministic for any thread count.
#pragma once

#include <cstddef>
#include <vector>

#include "absl/status/statusor.h"
#include "core/errormap/error_map.h"
#include "core/plan/inspection_plan.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

struct CoverageSettings {
  double distance_mm = 1.0;  // a location this close to a measured point is covered; > 0
  double sample_mm = 0;      // sub-triangle size; 0 = distance_mm / 2
  int threads = 0;           // 0 = all cores
};

struct CoverageResult {
  double distance_mm = 0, sample_mm = 0;  // used
  double surface = 0;                     // covered fraction of the whole CAD area
  std::vector<double> regions;            // per plan region, plan order; 0 for an empty region
  std::vector<double> points;             // per comparison point: of the area within its radius
  std::vector<float> triangles;           // per CAD triangle, for the reports' pictures
};

// `error_map` was computed against `part`; `plan` was resolved on `part`.
// InvalidArgument for bad settings or mismatched sizes.
absl::StatusOr<CoverageResult> ComputeCoverage(const ErrorMapResult& error_map,
                                               const TriangleMesh& part,
                                               const ResolvedInspectionPlan& plan,
                                               const CoverageSettings& settings);

}  // namespace surfinspect
