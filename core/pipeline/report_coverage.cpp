#include "core/pipeline/report_coverage.h"

namespace surfinspect {
namespace {

double Round3(double v) { return std::round(v * 1000) / 1000; }

}  // namespace

std::optional<ReportCoverage> ReportCoverageOf(const PlanOutcome& outcome) {
  if (!outcome.coverage_run) return std::nullopt;
  const CoverageResult& c = outcome.coverage;
  ReportCoverage out;
  out.distance_mm = Round3(c.distance_mm);
  out.surface = Round3(c.surface);
  for (std::size_t t = 0; t < c.triangles.size(); ++t) {
    const double f = Round3(c.triangles[t]);
    if (f >= 1) continue;
    out.triangles.push_back(t);
    out.covered.push_back(f);
  }
  return out;
}

absl::Status CheckReportCoverage(const std::optional<ReportCoverage>& coverage) {
  if (!coverage) return absl::OkStatus();
  const ReportCoverage& c = *coverage;
  if (c.covered.size() != c.triangles.size())
    return absl::DataLossError("report.coverage.covered: not one fraction per listed triangle");
  for (std::size_t k = 0; k < c.triangles.size(); ++k) {
    if (k > 0 && c.triangles[k] <= c.triangles[k - 1])
      return absl::DataLossError("report.coverage.triangles: ids not ascending");
    if (!(c.covered[k] >= 0 && c.covered[k] <= 1))
      return absl::DataLossError("report.coverage.covered: a fraction outside [0, 1]");
  }
  return absl::OkStatus();
}

}  // namespace surfinspect
