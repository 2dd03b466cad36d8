// The cell's part of the reports written beside report.json: each
// viewpoint's calibration status as cell.json records it (calibrated
// world_from_sensor, and the quality figures `cell-agent calibrate` stored).
#pragma once

#include <vector>

#include "client/cell/cell_config.h"
#include "core/report/html_sections.h"

namespace surfinspect::client {

// One entry per viewpoint of the cell, in the file's order.
std::vector<ViewpointCalibration> ViewpointCalibrations(const CellConfig& cell);

}  // namespace surfinspect::client
