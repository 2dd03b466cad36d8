// The HTML report's panels beside the 3D viewer, built from the typed report
// (core/pipeline/inspection_report.h) and the part's context. Every string taken from the report or
// the context is escaped (core/report/html_escape.h). Numbers the page's tests read back carry
// their exact JSON text in a data-value attribute.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/pipeline/inspection_report.h"

namespace surfinspect {

// A viewpoint's calibration as cell.json holds it.
struct ViewpointCalibration {
  std::string name;
  bool calibrated = false;  // has a calibrated world_from_sensor
  nlohmann::json quality;   // core's calibration quality JSON (rms_mm, converged, warnings, ...),
                            // null when not stored
};

struct HtmlReportContext {
  std::string part_id;
  std::string cell;                              // empty: not known
  std::vector<ViewpointCalibration> viewpoints;  // empty: not known
};

// The part verdict banner: part id, cell, verdict, the tolerance reason.
std::string VerdictBanner(const InspectionReport& report, const HtmlReportContext& context);

// Characteristics, failed rows first (otherwise in the report's order).
std::string CharacteristicsTable(const InspectionReport& report);

// Defects, one row per defect with data-defect="ID" (the viewer flies there).
std::string DefectsTable(const InspectionReport& report);

// How the scan was aligned (core/report/report_content.h's lines and
// references' table, as the PDF prints them); "" for the calibrated frame.
std::string AlignmentSection(const InspectionReport& report);

// Statistics over all points: the point counts, the statistics and the
// +-band counts, each with its report key.
std::string StatisticsTable(const InspectionReport& report);

// The report's settings (and inputs, the file names, when present).
std::string SettingsTable(const InspectionReport& report);

std::string CalibrationTable(const HtmlReportContext& context);

}  // namespace surfinspect
