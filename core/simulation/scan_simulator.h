// A virtual structured-light area sensor: a pinhole camera that ray-casts a
// part mesh with Embree and returns the organized cloud it would measure, in
// the SENSOR frame, in millimetres, with NaN where nothing valid is seen.
// Every imperfection is seeded and deterministic, and each pixel carries its
// ground truth, so the filter, the calibration and the error map can be
// scored against it.
//
// Sensor frame: +z along the optical axis (viewing direction), +x to the
// right in the image, +y down the image (rows), as in OpenCV.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "core/types/point_cloud.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

struct SensorIntrinsics {
  uint32_t width = 1024;             // pixels (columns)
  uint32_t height = 768;             // pixels (rows)
  double horizontal_fov_deg = 35.0;  // full horizontal field of view
  double min_range_mm = 250.0;       // points nearer than this are invalid
  double max_range_mm = 600.0;       // points farther than this are invalid
};

// A Gaussian deformation of the true surface: displacement along the
// surface normal of -depth_mm * exp(-r^2 / (2 sigma^2)), sigma = radius_mm/2,
// r = distance from `center_in_part` (part frame). depth_mm > 0 is a dent
// (into the material, below the CAD surface); depth_mm < 0 is a bump.
struct SurfaceDefect {
  Eigen::Vector3d center_in_part = Eigen::Vector3d::Zero();  // mm, on the surface
  double radius_mm = 5.0;  // where the deformation has fallen to exp(-2) = 13.5%
  double depth_mm = 0.1;
};

struct ScanOptions {
  double noise_sigma_mm = 0.0;      // Gaussian noise along the viewing ray
  double pulse_fraction = 0.0;      // fraction of valid pixels turned into pulses
  double pulse_min_mm = 2.0;        // pulse displacement along the ray, uniform
  double pulse_max_mm = 20.0;       //   in [min, max], random sign
  bool stripes = false;             // mixed pixels at depth discontinuities
  double stripe_min_jump_mm = 3.0;  // neighbour depth jump that makes a discontinuity
  uint32_t stripe_max_length = 6;   // pixels per stripe chain
  double stripe_probability = 0.5;  // chance a discontinuity pixel seeds a stripe
  std::vector<SurfaceDefect> defects;
  uint64_t seed = 1;
};

enum class PixelLabel : uint8_t {
  kNoData = 0,  // nothing hit, or out of range
  kGood = 1,    // a point on the (undeformed) CAD surface, plus noise
  kPulse = 2,   // displaced along the ray by 2-20 mm
  kStripe = 3,  // mixed pixel between two surfaces at a discontinuity
  kDefect = 4,  // on a planted dent or bump (|deviation| >= 1 um)
};

struct SimulatedScan {
  PointCloud cloud_in_sensor;      // organized width x height, mm
  std::vector<PixelLabel> labels;  // per pixel
  // Per pixel: signed deviation of the simulated (true, deformed) surface from
  // the CAD surface along its normal before noise, mm (+ above, - below);
  // NaN for no-data, pulse and stripe pixels.
  std::vector<float> true_deviation_mm;
  // Per pixel: id of the CAD triangle the ray hit, or UINT32_MAX.
  std::vector<uint32_t> triangle_id;
  // Diagnostics.
  std::size_t hits = 0, pulses = 0, stripe_pixels = 0, defect_pixels = 0;
};

// `mesh_in_part` is placed by `world_from_part`; the sensor sits at
// `world_from_sensor`. Fails on an invalid mesh, a non-positive size or
// field of view, or an Embree error.
absl::StatusOr<SimulatedScan> SimulateScan(const TriangleMesh& mesh_in_part,
                                           const Eigen::Isometry3d& world_from_part,
                                           const Eigen::Isometry3d& world_from_sensor,
                                           const SensorIntrinsics& intrinsics,
                                           const ScanOptions& options);

// Pinhole focal length in pixels for the intrinsics (fx = fy).
double FocalLengthPixels(const SensorIntrinsics& intrinsics);

// A sensor pose at `eye` (world, mm) looking at `target`, with image rows
// (+y) as close as possible to `down_hint`.
Eigen::Isometry3d LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                         const Eigen::Vector3d& down_hint = -Eigen::Vector3d::UnitY());

}  // namespace surfinspect
