// Trim-edge points against simulated truth: the pillar made with its +x end
// trimmed long by known amounts, scanned from the demo viewpoints with the
// demo's noise and filter.
#include "core/plan/edge_points.h"

#include <gtest/gtest.h>

#include <iostream>

#include "core/filter/link_clustering.h"
#include "core/registration/registration.h"
#include "core/simulation/demo_cell.h"
#include "tests/support/demo_scans.h"

namespace surfinspect {
namespace {

TEST(EdgePoints, ATrimmedEndIsFoundWithinAFifthOfAPixel) {
  const DemoCell cell = MakeDemoCell();
  const double half = 0.5 * cell.part_length_mm;
  PlanEdgePoint end;  // the top's end edge at +x
  end.name = "end";
  end.position_mm = {half, 0, PillarRidgeZ(half, cell.part_length_mm)};
  PlanEdgePoint flange;  // the left flange's outer edge, not changed
  flange.name = "flange";
  flange.position_mm = {-40, -76.08, PillarRidgeZ(-40, cell.part_length_mm) - 60};
  double worst = 0;
  for (double offset : {0.2, 0.5, 1.0}) {
    PillarFeatures made = cell.features;
    made.trim_offset_mm = offset;
    const testing::ScannedPart s = testing::ScanMadePart(cell, made, 30 + uint64_t(offset * 10));
    auto m = MeasureEdgePoints({end, flange}, cell.part, s.plan_views);
    ASSERT_TRUE(m.ok()) << m.status();
    for (int k = 0; k < 2; ++k) {
      const EdgePointMeasurement& r = (*m)[k];
      ASSERT_TRUE(r.measured) << k << ": " << r.reason;
      // The end's edge moved along +x; in the face's plane (tilted 2.3 deg
      // by the sag) that is offset * cos(2.3 deg) off the material.
      const double truth = k == 0 ? offset * std::cos(std::atan(0.04)) : 0.0;
      const double bound = std::max(0.03, 0.2 * r.pixel_pitch_mm);
      EXPECT_NEAR(r.value_mm, truth, bound) << (k == 0 ? "end" : "flange") << ", trim " << offset;
      EXPECT_GT(r.points, 40u);
      worst = std::max(worst, std::abs(r.value_mm - truth) / bound);
    }
  }
  std::cout << "worst edge error: " << worst << " of its bound\n";
}

TEST(EdgePoints, WithoutViewsOrBoundaryNothingIsMeasured) {
  const DemoCell cell = MakeDemoCell();
  PlanEdgePoint e;
  e.position_mm = {150, 0, 57};
  auto m = MeasureEdgePoints({e}, cell.part, {});
  ASSERT_TRUE(m.ok());
  EXPECT_FALSE((*m)[0].measured);
  EXPECT_NE((*m)[0].reason.find("organized views"), std::string::npos);
  TriangleMesh closed = MakeGaugeMesh();
  auto none = MeasureEdgePoints({e}, closed, {});
  ASSERT_TRUE(none.ok());
  EXPECT_NE((*none)[0].reason.find("no boundary"), std::string::npos);
}

}  // namespace
}  // namespace surfinspect
