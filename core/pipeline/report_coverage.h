// Where the scan saw the CAD, as report.json carries it ("coverage"; only
// when the plan judged coverage, so the reports of other plans keep their
// bytes): the distance within which a CAD location counted as seen, the
// covered fraction of the whole surface, and the CAD triangles not wholly
// covered with their covered fraction (core/plan/coverage.h), so that a
// reader (the HTML report's 3D view) can grey out what the sensor did not
// see without running the plan again. Fractions are rounded to 0.001 when
// the report is made; a triangle that rounds to 1 is not listed.
#pragma once

#include <cmath>
#include <cstddef>
#include <optional>
#include <vector>

#include "absl/status/status.h"
#include "core/plan/plan_evaluation.h"

namespace surfinspect {

struct ReportCoverage {
  double distance_mm = NAN, surface = NAN;
  std::vector<std::size_t> triangles;  // CAD triangle ids, ascending
  std::vector<double> covered;         // per listed triangle, in [0, 1)
};

// Set when `outcome` ran coverage.
std::optional<ReportCoverage> ReportCoverageOf(const PlanOutcome& outcome);

// DataLoss naming the field (report.coverage.covered, .triangles) when the
// columns differ in length, the ids are not ascending or a fraction is
// outside [0, 1].
absl::Status CheckReportCoverage(const std::optional<ReportCoverage>& coverage);

template <typename V, typename R>
void VisitReportCoverage(V& v, R& coverage) {
  v.Object("coverage", coverage, [](auto& w, auto& c) {
    w("distance_mm", c.distance_mm);
    w("surface", c.surface);
    w("triangles", c.triangles);
    w("covered", c.covered);
  });
}

}  // namespace surfinspect
