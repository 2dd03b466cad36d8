// A part's record from its report.json (schema surfinspect.report/2, see
// docs/inspection-plan.md): the verdict, every characteristic with its
// tolerance and its charted value (a comparison point's value_mm, a region's
// or the surface's mean_mm), and the defects. The files are the primary
// record, so the store is always filled from this one reading of them.
#pragma once

#include <string>

#include "absl/status/status.h"
#include "core/history/results_store.h"

namespace surfinspect {

// Sets verdict, characteristics and defects_json of `record`; `where` names
// the report in errors.
absl::Status FillFromReportJson(const std::string& report_json, const std::string& where,
                                PartRecord* record);

}  // namespace surfinspect
