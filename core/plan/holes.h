// Holes and slots measured on the scan: the sheet's edge around the
// nominal hole sampled in every view's grid (core/plan/edge_samples.h),
// then one circle (or slot) fitted to the samples of every view by
// geometric least squares with robust rejection (core/plan/profile_fit.h),
// and the arc of the edge the kept samples cover. Units mm, part frame.
#pragma once

#include <Eigen/Geometry>
#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/plan/edge_samples.h"
#include "core/plan/inspection_plan.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

struct HoleMeasurement {
  bool measured = false;
  std::string reason;  // why not measured, for people; "" when measured
  // In the hole's plan plane (through the plan's position_mm, normal to its
  // axis): the fitted centre, the deviation from the nominal centre (lies in
  // that plane) and the true position 2 |deviation| (ISO 1101, ASME Y14.5).
  Eigen::Vector3d measured_position_mm = Eigen::Vector3d::Constant(NAN);
  Eigen::Vector3d position_deviation_mm = Eigen::Vector3d::Constant(NAN);
  double true_position_mm = NAN;
  double diameter_mm = NAN, diameter_deviation_mm = NAN;  // a slot's width
  double length_mm = NAN, length_deviation_mm = NAN;      // slots only
  double form_mm = NAN;  // max - min residual of the edge points kept by the fit
  double rms_mm = NAN;   // of those residuals
  double arc_coverage_deg = 0;
  double pixel_pitch_mm = NAN;  // median distance of neighbouring rays on the face at the edge
  std::size_t edge_points = 0;  // kept by the fit
  std::size_t samples = 0;      // found, before the fit's rejection
  std::size_t wall_points = 0;  // of the samples, from the hole's wall
  std::size_t views = 0;        // that gave samples
};

// One measurement per plan hole, in plan order. `views` empty: every hole
// is not measured (the reason says the organized views are needed).
// `rays`, when given, is PrepareRayViews(views), made once by a caller that
// also measures edge points. Cancelled when `cancel` is raised.
absl::StatusOr<std::vector<HoleMeasurement>> MeasureHoles(
    const std::vector<PlanHole>& holes, const std::vector<PlanView>& views,
    const EdgeSettings& settings = {}, const std::atomic<bool>* cancel = nullptr,
    const std::vector<RayView>* rays = nullptr);

}  // namespace surfinspect
