// What a printed report shows, read from the typed report
// (core/pipeline/inspection_report.h), with a plan or without one (then the
// +-tolerance verdict and no tables): the
// verdict, the statistics, the characteristics table with failed rows first,
// the defects table and the histogram. Millimetres, part frame. Numbers are
// formatted once here, so every renderer prints the same text.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "core/errormap/error_map.h"
#include "core/pipeline/inspection_report.h"
#include "core/plan/defects.h"

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
  // CharacteristicHeader()'s columns, one CharacteristicRow per characteristic
  ReportTable characteristics;
  ReportTable defects;  // id, kind, region, peak, peak from, area, extent, points, centroid
  std::vector<Defect> defect_marks;  // id and centroid of each defect, for the map
  Histogram histogram;
  // How the scan was aligned (none for the calibrated frame): its lines for
  // people, then a row per RPS reference (AlignmentHeader()).
  std::vector<std::string> alignment_lines;
  ReportTable alignment;
};

// The alignment's lines (core/pipeline/report_alignment.h): the correction
// against its maximum and the RMS, the failure, the caution. None for the
// calibrated frame. The CLI prints the same lines.
std::vector<std::string> AlignmentLines(const std::optional<ReportAlignment>& alignment);
// reference, kind, measured, locks (a direction a line), before mm, after
// mm (one per direction), points; a reference not measured is a failed row.
const std::vector<std::string>& AlignmentHeader();
ReportTable AlignmentTable(const std::optional<ReportAlignment>& alignment);

// A millimetre value as the report prints it: "%+.3f", "-" for null/NaN.
std::string FormatMm(double v);
// A characteristic's coverage as the reports print it: "97.3% (min 90%)",
// "-" when the report has none.
std::string CoverageText(const ReportCharacteristic& c);

// The characteristics table's columns: name, type, verdict, tolerance,
// value, min, max, in tol / arc, points, coverage.
const std::vector<std::string>& CharacteristicHeader();
inline constexpr std::size_t kVerdictColumn = 2;  // its cell is the report's verdict
// One characteristic's row. A surface, region or section shows its band,
// mean, extremes and fraction within; a point its value. A hole shows, one
// per line, its size's band ("Ø" diameter, "W" a slot's width, "L" its
// length) and its true position zone ("TP"); the measured sizes with their
// deviations ("Ø 8.012 (+0.012)") and the true position against its zone
// ("TP 0.310 / 0.300"); and the arc of its edge seen ("arc 351°"), not the
// surface statistics, which it has none of. Lines are separated by '\n'.
std::vector<std::string> CharacteristicRow(const ReportCharacteristic& c);

// A hole's (a slot's) parts judged each on its own: "pass", "fail" or
// "not_measured" (all three when the hole was not measured; `length` is ""
// for a round hole). The size passes inside its band as ToleranceBand::
// Contains says, the position when the true position is within its zone:
// the rules that made the hole's verdict (core/plan/characteristics.h).
struct HoleVerdicts {
  std::string size, length, position;
};
HoleVerdicts HoleVerdictsOf(const ReportCharacteristic& c);

// DataLoss unless the report has its tolerance band and colour range (both
// > 0). Missing counts, statistics, histogram, characteristics or defects
// show as "-" or empty.
absl::StatusOr<ReportContent> ReportContentFrom(const InspectionReport& report);

}  // namespace surfinspect
