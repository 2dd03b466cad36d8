// The core's results as the report's types: a judged characteristic and a
// found defect, field by field (core/pipeline/inspection_report.h holds the
// codec; this is the one place a result's field meets its report field).
#pragma once

#include "core/pipeline/inspection_report.h"

namespace surfinspect {

ReportCharacteristic ReportCharacteristicOf(const CharacteristicResult& c);
ReportDefect ReportDefectOf(const Defect& d);

}  // namespace surfinspect
