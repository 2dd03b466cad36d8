// The built-in demo cell: a procedural stamped sheet-metal "pillar" (a
// hat-channel profile ~300 mm long with flanges and bends, a few thousand
// triangles, outward CCW normals), a 6-DOF calibration gauge (a stepped plate
// with spheres of different radii), and five viewpoints ~400 mm above the
// part's top ridge. Nothing is read from disk; everything is generated
// (client/cell/demo_cell_files.h writes it as a cell folder).
//
// Calibration follows the paper's eq. (1): for viewpoint i the gauge sits at
// its own surveyed pose `world_from_gauge` under that viewpoint, so
// world_from_sensor_i = world_from_gauge_i * gauge_from_sensor_i.
#pragma once

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/simulation/pillar.h"
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
  TriangleMesh part;  // part frame, mm: MakePillarMesh(part_length_mm, features)
  double part_length_mm = 300;
  PillarFeatures features;  // the CAD's holes
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

// A UV sphere of radius r (mm) about c: `slices` around the z axis and
// `stacks` from pole to pole; vertices on the sphere, outward CCW normals.
// Its facets lie inside the sphere by at most r (1 - cos(pi / min(slices, 2 stacks)))
// at their centres.
void AddUvSphere(TriangleMesh& mesh, const Eigen::Vector3d& c, double r, int slices, int stacks);
// The calibration gauge alone (plate in z <= 0, spheres and steps above).
TriangleMesh MakeGaugeMesh();

// A production part of the demo: its id and the defects planted on it.
struct DemoPart {
  int number = 1;                      // 1-based
  std::string part_id;                 // "part-001", ...
  std::vector<SurfaceDefect> defects;  // two dents and a bump on the ridge
  // The part as made where it differs from the CAD (shifted or resized
  // holes, an offset trim edge); unset: as the CAD.
  std::optional<PillarFeatures> manufactured;
  // Where the part sits in its fixture, off where the CAD says (clamps,
  // pins, spring-back): its points p lie at world_from_part * in_fixture * p.
  // The calibrated cell sees it displaced; an RPS or best-fit alignment
  // recovers in_fixture^-1 (core/plan/alignment.h).
  Eigen::Isometry3d in_fixture = Eigen::Isometry3d::Identity();
};

// Parts 1..count with their defects, drawn from `scan_seed` (the seed of the
// production scans' ScanOptions).
std::vector<DemoPart> MakeDemoParts(const DemoCell& cell, int count, uint64_t scan_seed);

// An RPS alignment for the demo part (docs/alignment.md): its round holes
// of the top nearest (-110, 0) and (35, 10) by their names in
// PlanHolesJson(ListHoles(cell.part)) order, and four surface points, two
// on the top and two on the flanges, clear of the holes. A plan's
// "alignment" block.
nlohmann::json DemoRpsAlignment(const DemoCell& cell);

// The gauge scan of viewpoint v (index into cell.viewpoints): `scan`'s noise
// and outliers without defects, seeded by scan.seed and v.
absl::StatusOr<SimulatedScan> SimulateDemoGaugeScan(const DemoCell& cell, std::size_t v,
                                                    const ScanOptions& scan);

// The production scan of `part` from viewpoint v: `scan` plus the part's
// defects, seeded by scan.seed, the part's number and v.
absl::StatusOr<SimulatedScan> SimulateDemoPartScan(const DemoCell& cell, const DemoPart& part,
                                                   std::size_t v, const ScanOptions& scan);

}  // namespace surfinspect
