#include "tests/support/demo_scans.h"

#include <gtest/gtest.h>

namespace surfinspect::testing {

namespace {

ScannedPart Scan(const DemoCell& cell, const DemoPart& part, uint64_t seed,
                 const std::vector<std::size_t>& which, const LinkClusteringSettings& filter) {
  ScanOptions opt;
  opt.noise_sigma_mm = 0.015;
  opt.seed = seed;
  std::vector<std::size_t> views = which;
  if (views.empty())
    for (std::size_t v = 0; v < cell.viewpoints.size(); ++v) views.push_back(v);
  ScannedPart s;
  for (std::size_t v : views) {
    auto scan = SimulateDemoPartScan(cell, part, v, opt);
    EXPECT_TRUE(scan.ok()) << scan.status();
    if (!scan.ok()) continue;
    s.views.push_back(
        {cell.viewpoints[v].name, scan->cloud_in_sensor, cell.viewpoints[v].world_from_sensor});
  }
  EXPECT_TRUE(FilterViews(s.views, filter).ok());
  for (const ViewScan& v : s.views)
    s.plan_views.push_back(
        {v.name, &v.cloud_in_sensor, cell.world_from_part.inverse() * v.world_from_sensor});
  return s;
}

}  // namespace

ScannedPart ScanMadePart(const DemoCell& cell, const PillarFeatures& made, uint64_t seed,
                         const std::vector<std::size_t>& which,
                         const LinkClusteringSettings& filter) {
  DemoPart part;
  part.number = int(seed);
  part.manufactured = made;
  return Scan(cell, part, seed, which, filter);
}

ScannedPart ScanDemoPart(const DemoCell& cell, const DemoPart& part, uint64_t seed) {
  return Scan(cell, part, seed, {}, LinkClusteringSettings::ForInspection());
}

}  // namespace surfinspect::testing
