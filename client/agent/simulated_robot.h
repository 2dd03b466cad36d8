// The simulated robot for demos and tests: scans new parts with the virtual
// area sensor at the cell's viewpoints, plants random dents and bumps on the
// ridge, and drops them into the inbox exactly as a scanner would (scans
// first, each written atomically, then the DONE marker). The planted defects
// go into <part>/truth.json beside the scans.
#pragma once

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

// As below, scanned by a robot that has drifted.
absl::StatusOr<std::vector<std::string>> SimulateParts(const CellConfig& cell,
                                                       const std::string& inbox, int count,
                                                       uint64_t seed, const RobotDrift& drift);

// Returns the new part ids.
absl::StatusOr<std::vector<std::string>> SimulateParts(const CellConfig& cell,
                                                       const std::string& inbox, int count,
                                                       uint64_t seed);

}  // namespace surfinspect::client
