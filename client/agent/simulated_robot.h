// The simulated robot for demos and tests: scans new parts with the virtual
// area sensor at the cell's viewpoints, plants random dents and bumps on the
// ridge, and drops them into the inbox exactly as a scanner would (scans
// first, each written atomically, then the DONE marker). cell.json's
// optional "simulation" block sets the scanner's noise_sigma_mm (0.015),
// pulse_fraction (0.003) and stripes (true). The planted defects
// go into <part>/truth.json beside the scans, and so does the process drift
// when one is asked for (a bump that grows from part to part, or that
// appears at part k), so that trend tests know the truth.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "client/cell/cell_config.h"

namespace surfinspect::client {

// A robot that has drifted at one viewpoint: there the sensor really stands
// `mm` away from its taught pose (a translation along a unit direction drawn
// from `seed`; the rotation is kept). Empty view or mm = 0: no drift.
struct RobotDrift {
  std::string view;
  double mm = 0;
  uint64_t seed = 1;
};
// "VIEW:MM", e.g. "v2:0.02" (mm >= 0); InvalidArgument naming the text otherwise.
absl::StatusOr<RobotDrift> ParseRobotDrift(const std::string& text);

// The gauge (mesh in the gauge frame, placed by vp.world_from_gauge) scanned
// now at viewpoint vp, as SimulateParts' robot would: same noise and
// outliers as the part scans, seeded by `seed` and the view.
absl::StatusOr<PointCloud> SimulateGaugeScan(const CellConfig& cell, const TriangleMesh& gauge,
                                             const CellViewpoint& vp, const RobotDrift& drift,
                                             uint64_t seed);

// A systematic change of the surface across the parts of one run, as a
// Gaussian bump (scan_simulator.h SurfaceDefect, + above the CAD) whose
// height depends on the part's index k = 0, 1, ... in the run:
//   "bow:RATE[:X,Y,R]"       height RATE * k mm (a bow that grows per part)
//   "shift:AMOUNT@K[:X,Y,R]" height AMOUNT mm from the K-th part (1-based) on
// centred on the part's surface at (X, Y) in the part frame (default: the
// middle of the part's x extent, y = 0: the demo part's ridge) with radius R
// mm (default 40; the bump is exp(-2) of its height at R). The random
// defects of a drifting run stay clear of the bump, so that the drift is
// observed alone.
struct SurfaceDrift {
  enum class Kind { kNone, kBow, kShift } kind = Kind::kNone;
  double amount_mm = 0;                      // bow: per part; shift: the step
  int from_part = 1;                         // shift: the first part (1-based) with the step
  std::optional<Eigen::Vector2d> center_xy;  // part frame, mm; unset = the default
  double radius_mm = 40;
  std::string spec;  // as given
  // The bump's height on the part with index k (0-based), mm.
  double HeightAt(int k) const;
};
// InvalidArgument naming the spec and what is wrong with it.
absl::StatusOr<SurfaceDrift> ParseSurfaceDrift(const std::string& spec);

// Returns the new part ids. `drift` changes the parts' surface, `robot`
// the pose the sensor really scans from. `hole_shift_mm` > 0: every third
// part (the 3rd, 6th, ...) is made with the CAD's first hole (ListHoles
// order) moved this far along +x in its plane (core/simulation/
// hole_changes.h), its truth in truth.json's "holes". `fixture_error_mm` >
// 0: every part sits off in its fixture by a random rigid motion of up to
// this many mm and half as many degrees (docs/alignment.md), its truth in
// truth.json's "fixture".
absl::StatusOr<std::vector<std::string>> SimulateParts(
    const CellConfig& cell, const std::string& inbox, int count, uint64_t seed,
    const SurfaceDrift& drift = {}, const RobotDrift& robot = {}, double hole_shift_mm = 0,
    double fixture_error_mm = 0);

// A part's placement in its fixture, off by up to `mm` (a random direction)
// and mm / 2 degrees (about a random axis through the part's origin); its
// truth as truth.json's "fixture": the matrix (4 x 4 row-major, part frame:
// the part's points p sit at world_from_part * in_fixture * p), the
// translation and the rotation angle.
Eigen::Isometry3d RandomFixtureError(std::mt19937_64& rng, double mm);
nlohmann::json FixtureTruth(const Eigen::Isometry3d& in_fixture);

}  // namespace surfinspect::client
