// The demo cell as a cell folder on disk, the layout `surfinspect demo-cell`
// writes and the CLI, the cell-agent and the tests read:
//   DIR/part.stl, DIR/gauge.stl           CAD meshes (mm)
//   DIR/cell.json                         viewpoints, poses, sensor, tolerance
//   DIR/gauge_scans/<view>.pcd            one gauge scan per viewpoint
//   DIR/scans/part-NNN/<view>.pcd         production scans with planted defects
//   DIR/truth/part-NNN/<view>.json        outlier pixels of each scan
//   DIR/truth/parts.json                  the planted defects of every part
//   DIR/acceptance/artefacts.json         acceptance artefacts (core/acceptance/artefacts.h)
//                                         with their simulated truth
//   DIR/acceptance/scans/<name>/<view>.pcd   their scans (binary_compressed)
// Scans are organized binary PCD in the sensor frame. core/simulation makes
// the data; this file only writes it.
#pragma once

#include <string>

#include "absl/status/status.h"
#include "core/simulation/demo_cell.h"

namespace surfinspect::client {

struct DemoWriteOptions {
  int parts = 1;
  ScanOptions scan;        // noise/outliers for all scans; production scans add defects
  bool acceptance = true;  // write DIR/acceptance/ (core/simulation/acceptance_artefacts.h)
};

absl::Status WriteDemoCell(const std::string& dir, const DemoCell& cell,
                           const DemoWriteOptions& options);

}  // namespace surfinspect::client
