// report.pdf, the part's inspection report for the quality file: A4
// portrait, text selectable, fonts embedded (core/report/pdf_canvas.h).
// Page 1: a header (part, cell, time, software version), the verdict
// banner, the error map (three orthographic views along -z, -y and -x for a
// merged cloud; the sensor grid for a single organized view) with the
// defects' ids, the colour bar with the tolerance band bracketed, the
// log-count histogram on the same deviation axis, and the statistics. Then
// the characteristics table (failed rows first) and the defects table,
// continued on as many pages as they need; when the report has sections,
// pages of section plots follow, six to a page (core/report/section_plot.h).
// The content comes from the typed report (core/report/report_content.h);
// the maps are drawn by core/report/error_map_png.h's renderer.
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/pipeline/inspection_report.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

struct PdfReportInput {
  std::string part_id;
  std::string cell;                                  // "" = not given
  std::string time_utc;                              // e.g. "2026-12-01 11:40:00 UTC"; "" = now
  const InspectionReport* report = nullptr;          // with a plan, or an error map's alone
  const PointCloud* points_in_part = nullptr;        // the scanned cloud, part frame, mm
  const std::vector<float>* deviation_mm = nullptr;  // per point of points_in_part
};

// The software that writes the report, e.g. "surfinspect 0.1.0".
std::string SoftwareVersion();

// The PDF bytes. InvalidArgument when the inputs are missing or their sizes
// differ, DataLoss for a report without the required fields.
absl::StatusOr<std::string> RenderPdfReport(const PdfReportInput& input);

// RenderPdfReport, written atomically.
absl::Status WritePdfReport(const std::string& path, const PdfReportInput& input);

}  // namespace surfinspect
