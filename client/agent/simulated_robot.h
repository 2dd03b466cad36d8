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

// Returns the new part ids.
absl::StatusOr<std::vector<std::string>> SimulateParts(const CellConfig& cell,
                                                       const std::string& inbox, int count,
                                                       uint64_t seed);

}  // namespace surfinspect::client
