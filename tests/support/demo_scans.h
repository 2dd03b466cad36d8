// A demo part made with known features (core/simulation/pillar.h), scanned
// from demo viewpoints with the demo's noise (0.015 mm) and filtered as
// inspect does: the views as the plan measures edges on them, with the
// true (calibrated) poses. For the hole and edge-point tests.
#pragma once

#include <cstdint>
#include <vector>

#include "core/filter/link_clustering.h"
#include "core/plan/edge_samples.h"
#include "core/registration/registration.h"
#include "core/simulation/demo_cell.h"

namespace surfinspect::testing {

struct ScannedPart {
  std::vector<ViewScan> views;
  std::vector<PlanView> plan_views;  // point into `views`: keep the struct in place
};

// `which`: indices into cell.viewpoints; empty: all of them. `filter`:
// the inspection preset unless given (a coarser sensor needs a longer link).
ScannedPart ScanMadePart(
    const DemoCell& cell, const PillarFeatures& made, uint64_t seed,
    const std::vector<std::size_t>& which = {},
    const LinkClusteringSettings& filter = LinkClusteringSettings::ForInspection());

// Any demo part (displaced in its fixture, with defects), scanned and
// filtered likewise from all the cell's viewpoints.
ScannedPart ScanDemoPart(const DemoCell& cell, const DemoPart& part, uint64_t seed);

}  // namespace surfinspect::testing
