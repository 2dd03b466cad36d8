// Trim-edge points measured on the scan: at a point of the CAD's boundary,
// the sheet's edge sampled in every view's grid (core/plan/edge_samples.h)
// within +-radius along the CAD edge, and the edge's offset across it in
// the face's plane: the mean of the samples' signed distances from the
// nominal edge (+ off the material: the sheet reaches farther than drawn),
// after leaving out samples beyond 3 robust sigmas. A straight edge along
// the pixel rows gives every sample of one view the same phase against the
// grid; the default radius of 5 mm spans enough rows that a few degrees of
// tilt sweep the phase through whole pixels. Units mm, part frame.
#pragma once

#include <atomic>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/plan/edge_samples.h"
#include "core/plan/inspection_plan.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

struct EdgePointMeasurement {
  bool measured = false;
  std::string reason;      // why not measured; "" when measured
  double value_mm = NAN;   // the measured edge's offset, + off the material
  std::size_t points = 0;  // samples kept
  double pixel_pitch_mm = NAN;
  std::size_t views = 0;
};

// One measurement per plan edge point, in plan order; `part` is the CAD
// mesh the plan was validated against. No views: not measured. `rays`,
// when given, is PrepareRayViews(views) (as for MeasureHoles).
absl::StatusOr<std::vector<EdgePointMeasurement>> MeasureEdgePoints(
    const std::vector<PlanEdgePoint>& points, const TriangleMesh& part,
    const std::vector<PlanView>& views, const EdgeSettings& settings = {},
    const std::atomic<bool>* cancel = nullptr, const std::vector<RayView>* rays = nullptr);

}  // namespace surfinspect
