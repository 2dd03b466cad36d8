// The built-in demo cell: a procedural stamped sheet-metal "pillar" (a
// hat-channel profile ~300 mm long with flanges and bends, a few thousand
// triangles, outward CCW normals), a 6-DOF calibration gauge (a stepped plate
// with spheres of different radii), and five viewpoints ~400 mm above the
// part's top ridge. Nothing is read from disk; everything is generated.
//
// Calibration follows the paper's eq. (1): for viewpoint i the gauge sits at
// its own surveyed pose `world_from_gauge` under that viewpoint, so
// world_from_sensor_i = world_from_gauge_i * gauge_from_sensor_i.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "core/simulation/scan_simulator.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

struct DemoViewpoint {
  std::string name;                             // "v1".."v5"
  Eigen::Isometry3d world_from_sensor;          // the true (taught, repeatable) pose
  Eigen::Isometry3d nominal_world_from_sensor;  // the robot's belief: off by mm/deg
  Eigen::Isometry3d world_from_gauge;           // where the gauge is surveyed for this view
};

struct DemoCell {
  TriangleMesh part;  // part frame, mm
  Eigen::Isometry3d world_from_part;
  TriangleMesh gauge;  // gauge frame, mm
  std::vector<DemoViewpoint> viewpoints;
  SensorIntrinsics intrinsics;
};

struct DemoCellOptions {
  double part_length_mm = 300.0;
  double nominal_error_mm = 3.0;   // robot nominal pose error, translation
  double nominal_error_deg = 2.0;  // robot nominal pose error, rotation
  uint64_t seed = 42;
};

DemoCell MakeDemoCell(const DemoCellOptions& options = {});

// The pillar part alone, e.g. for tests (hat channel along +x, top ridge at
// the highest z, centred on the origin).
TriangleMesh MakePillarMesh(double length_mm = 300.0);
// The calibration gauge alone (plate in z <= 0, spheres and steps above).
TriangleMesh MakeGaugeMesh();

// Writes DIR/{part.stl, gauge.stl, cell.json, scans/, gauge_scans/, truth/}:
// for each viewpoint a gauge scan and `parts` production scans with planted
// defects (organized binary PCD) and their ground truth as JSON.
struct DemoWriteOptions {
  int parts = 1;
  ScanOptions scan;  // noise/outliers for production scans; defects are added
};
absl::Status WriteDemoCell(const std::string& dir, const DemoCell& cell,
                           const DemoWriteOptions& options);

}  // namespace surfinspect
