// The edge of the sheet near a nominal contour, sampled in the views' own
// grids (each view is organized: where the sheet ends, a pixel on the sheet
// has a neighbour that is not). Holes and slots (core/plan/holes.h) and
// trim-edge points (core/plan/edge_points.h) are measured on these samples.
//
// Per view, in the window of pixels around the nominal edge:
//  1. the local face: a plane fitted (robustly) to the points on the sheet
//     on the material side of the nominal edge, in the contour's frame;
//  2. edge samples: for a pixel on the face with a 4-neighbour that is not
//     (no data, filtered out, or below the face: a wall, or what lies
//     beyond the edge) and whose ray meets the face farther off the
//     material, the midpoint of the two pixels' rays met with the face.
//     Rays, not points: noise along the viewing ray leaves the meeting point
//     where it was, and the true edge lies uniformly between the two rays,
//     so the midpoint has no bias, where the last measured point alone
//     would be half a pixel inside the material on average;
//  3. the wall: points below the face by more than its noise and near the
//     edge are points of the sheet's cut face, seen by a tilted view;
//     projected into the plane they are edge samples too (a wall point
//     taken for the face would put the edge off the material).
//
// Rays come from each view's pinhole model, fitted from its organized cloud
// in the sensor frame (core/plan/pinhole_rays.h) and placed by its
// calibrated pose. Units mm, part frame.
#pragma once

#include <Eigen/Geometry>
#include <functional>
#include <string>
#include <vector>

#include "core/plan/cad_holes.h"
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

struct EdgeSettings {
  double band_mm = 2.0;      // edge pixels within +-band of the nominal edge are searched
  double annulus_mm = 3.0;   // the face is fitted out to band + annulus into the material
  double max_wall_mm = 5.0;  // points this far below the face are no longer wall
};

// A nominal edge: its plane frame (the axis is the face's normal, on the
// scanned side), the signed in-plane distance from the edge (+ into the
// material), and an outline around the region to search (in-plane points
// whose projections bound the pixel window).
struct EdgeContour {
  PlaneFrame frame;
  std::function<double(const Eigen::Vector2d&)> into_material;
  std::vector<Eigen::Vector2d> outline;
};

// A view with its fitted rays; views whose grids are not a pinhole's are
// left out (an unorganized view has no edges to find).
struct RayView {
  const PlanView* view = nullptr;
  PinholeRays rays;
  Eigen::Isometry3d sensor_from_part;
};
std::vector<RayView> PrepareRayViews(const std::vector<PlanView>& views);

struct EdgeSamples {
  std::vector<Eigen::Vector2d> points;  // in the contour's plane
  std::vector<double> steps;            // per ray-pair sample: the two rays' distance on the face
  std::size_t wall = 0;                 // samples from the wall
  std::size_t views = 0;                // views that gave samples
  double PixelPitch() const;            // median of steps; NaN without any
};

EdgeSamples SampleEdge(const std::vector<RayView>& views, const EdgeContour& contour,
                       const EdgeSettings& settings);

}  // namespace surfinspect
