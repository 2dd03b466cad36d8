#include "core/history/part_record.h"

#include "absl/strings/str_cat.h"
#include "core/pipeline/inspection_report.h"

namespace surfinspect {

absl::Status FillFromReportJson(const std::string& text, const std::string& where,
                                PartRecord* record) {
  const absl::StatusOr<InspectionReport> report = ParseReport(text);
  if (!report.ok())
    return absl::DataLossError(absl::StrCat(where, ": ", report.status().message()));
  if (report->verdict.empty()) return absl::DataLossError(absl::StrCat(where, ": no verdict"));
  record->verdict = report->verdict;
  record->characteristics.clear();
  for (const ReportCharacteristic& c : report->characteristics) {
    CharacteristicRecord r;
    r.name = c.name;
    r.type = c.type;
    r.verdict = c.verdict;
    r.mean_mm = c.mean_mm;
    r.min_mm = c.min_mm;
    r.max_mm = c.max_mm;
    r.stddev_mm = c.stddev_mm;
    r.value_mm = c.has_value() ? c.value_mm : c.mean_mm;
    r.lower_mm = c.tolerance.lower_mm;
    r.upper_mm = c.tolerance.upper_mm;
    r.points = static_cast<int64_t>(c.points);
    if (c.is_hole()) {
      r.size_mm = c.measured_diameter_mm;
      r.size_deviation_mm = c.diameter_deviation_mm;
      r.true_position_mm = c.true_position_mm;
      r.position_tolerance_mm = c.position_tolerance_mm;
      r.length_mm = c.measured_length_mm;
      r.length_deviation_mm = c.length_deviation_mm;
      r.length_lower_mm = c.length_tolerance.lower_mm;
      r.length_upper_mm = c.length_tolerance.upper_mm;
    }
    record->characteristics.push_back(std::move(r));
  }
  record->defects_json = EncodeDefects(report->defects).dump();
  return absl::OkStatus();
}

}  // namespace surfinspect
