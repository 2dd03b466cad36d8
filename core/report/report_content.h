// What a printed report shows, read from report.json (schema
// "surfinspect.report/2", docs/inspection-plan.md) or from the errormap
// command's report (no plan: the +-tolerance verdict, no tables): the
// verdict, the statistics, the characteristics table with failed rows first,
// the defects table and the histogram. Millimetres, part frame. Numbers are
// formatted once here, so every renderer prints the same text.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "core/errormap/defects.h"
#include "core/errormap/error_map.h"

namespace surfinspect {

struct ReportTable {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;  // each as long as header
  std::vector<bool> failed;                    // per row
};

struct ReportContent {
  bool pass = false;
  std::string verdict;  // "pass" / "fail"
  std::string reason;   // the +-tolerance verdict's one line
  double tolerance_mm = 0, color_range_mm = 0;
  std::vector<std::pair<std::string, std::string>> statistics;  // label, value
  ReportTable characteristics;  // name, type, verdict, tolerance, value, min, max, in tol, points
  ReportTable defects;          // id, kind, region, peak, area, extent, points, centroid
  std::vector<Defect> defect_marks;  // id and centroid of each defect, for the map
  Histogram histogram;
};

// A millimetre value as the report prints it: "%+.3f", "-" for null/NaN.
std::string FormatMm(double v);

// DataLoss naming the field when a required one (tolerance.band_mm,
// tolerance.verdict unless there is a part verdict, color_range_mm) is
// missing, or when a field that is present has the wrong type. Missing
// points, statistics, histogram, characteristics or defects show as "-" or
// empty.
absl::StatusOr<ReportContent> ReportContentFromJson(const nlohmann::json& report);

}  // namespace surfinspect
