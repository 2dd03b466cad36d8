// Holes and slots measured on the scan, at their edges in the views' own
// grids (each view is organized: where the sheet ends, a pixel on the sheet
// has a neighbour that is not).
//
// Per hole and view, in a window of pixels around the nominal edge:
//  1. the local face: a plane fitted (robustly) to the points on the sheet
//     in an annulus outside the nominal edge, in the hole's frame;
//  2. edge samples: for a pixel on the face with a 4-neighbour that is not
//     (no data, no match, or below the face: the hole's wall or what lies
//     under the hole) and whose ray meets the face nearer the hole's inside,
//     the midpoint of the two pixels' rays met with the face. Rays, not
//     points: noise along the viewing ray leaves the meeting point where it
//     was, and the true edge lies uniformly between the two rays, so the
//     midpoint has no bias, where the last measured point alone would be
//     half a pixel outside the edge on average (a pixel's bias in diameter);
//  3. the wall: points below the face by more than its noise and near the
//     edge are points of the hole's wall, seen by a tilted view; projected
//     into the hole's plane they are rim samples (a wall point taken for the
//     face would put the edge inside the hole);
// then one circle (or slot) is fitted to the samples of every view by
// geometric least squares with robust rejection (core/plan/profile_fit.h).
//
// Rays come from each view's pinhole model, fitted from its organized cloud
// in the sensor frame (x/z and y/z affine in column and row) and placed by
// its calibrated pose. Units mm, part frame.
#pragma once

#include <Eigen/Geometry>
#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/plan/inspection_plan.h"
#include "core/plan/pinhole_rays.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

// An organized view as the plan sees it: its grid in the sensor frame, as
// filtered (a removed point is no data), and the sensor's calibrated pose in
// the part frame (the frame the error map was computed in).
struct PlanView {
  std::string name;
  const PointCloud* grid_in_sensor = nullptr;  // organized; outlives the evaluation
  Eigen::Isometry3d part_from_sensor = Eigen::Isometry3d::Identity();
};

struct HoleSettings {
  double band_mm = 2.0;      // edge pixels within +-band of the nominal edge are searched
  double annulus_mm = 3.0;   // the local face is fitted out to band + annulus from the edge
  double max_wall_mm = 5.0;  // points this far below the face are no longer wall
  std::size_t min_samples = 12;
};

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
// Cancelled when `cancel` is raised.
absl::StatusOr<std::vector<HoleMeasurement>> MeasureHoles(
    const std::vector<PlanHole>& holes, const std::vector<PlanView>& views,
    const HoleSettings& settings = {}, const std::atomic<bool>* cancel = nullptr);

}  // namespace surfinspect
