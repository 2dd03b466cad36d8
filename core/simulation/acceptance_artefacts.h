// The acceptance artefacts of the demo cell (core/acceptance/artefacts.h) in
// the simulator: a matt sphere (Ø 25 mm) under three viewpoints, a ball bar
// (two Ø 25 mm spheres 200 mm apart) in eight positions and orientations
// across the measuring volume, four of which no single viewpoint covers (each
// sphere is taken from its own view), and a flat plate. Placements are in
// the part's frame (where the part sits during production), moved to the
// world by the cell's world_from_part; the part itself is not in the scene.
//
// Planted errors, so that the figures have a known truth: the simulated
// sphere and ball bar differ from their calibrated values in artefacts.json
// by `sphere_error_mm` and `length_error_mm`, and the plate carries a
// centred Gaussian dent of `plate_dent_mm` (core/simulation/scan_simulator.h).
// Spheres are UV meshes fine enough that their facets lie within 0.25 µm of
// the true sphere.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/acceptance/artefacts.h"
#include "core/simulation/demo_cell.h"

namespace surfinspect {

struct AcceptanceArtefactOptions {
  double sphere_diameter_mm = 25.0;  // calibrated
  double sphere_error_mm = 0.004;    // true - calibrated
  double length_mm = 200.0;          // calibrated ball-bar length
  double length_error_mm = 0.006;    // true - calibrated
  double plate_dent_mm = 0.004;      // depth of the plate's dent
  MaxPermissibleErrors mpe{0.12, 0.02, 0.02, 0.12};
};

// One object in the scene: a mesh in its own frame, its pose, its defects.
struct AcceptanceObject {
  std::shared_ptr<const TriangleMesh> mesh;
  Eigen::Isometry3d world_from_object = Eigen::Isometry3d::Identity();
  std::vector<SurfaceDefect> defects;               // in the object's frame
  std::vector<Eigen::Vector3d> true_centres_world;  // spheres: 1, ball bar: a, b
};

struct AcceptanceScene {
  Artefacts artefacts;  // what artefacts.json says: calibrated values and hints
  std::map<std::string, AcceptanceObject> objects;  // by measurement name
  // The simulated truth of each figure (noise-free), mm.
  double true_sphere_diameter_mm = 0, true_length_mm = 0;
  double true_flatness_mm = 0;  // range of the dent over the evaluated disc
};

AcceptanceScene MakeDemoAcceptance(const DemoCell& cell, const AcceptanceArtefactOptions& o = {});

// The scan of measurement `name` from viewpoint `view` of `cell`, from the
// sensor at `world_from_sensor` (normally the viewpoint's true pose),
// seeded by scan.seed and the measurement. NotFound for an unknown name.
absl::StatusOr<SimulatedScan> SimulateAcceptanceScan(const DemoCell& cell,
                                                     const AcceptanceScene& scene,
                                                     const std::string& name,
                                                     const Eigen::Isometry3d& world_from_sensor,
                                                     const ScanOptions& scan);

// Index of viewpoint `view` in cell.viewpoints, or NotFound.
absl::StatusOr<std::size_t> ViewIndex(const DemoCell& cell, const std::string& view);

}  // namespace surfinspect
