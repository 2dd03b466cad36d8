// report.html: one self-contained page per part that opens from the results
// folder with no server and no network. Beside a three.js viewer of the
// scanned points (part frame, coloured with the error map's palette, grey
// where unmatched; the CAD mesh as a translucent overlay that can be
// switched off; defects marked by their ids) it shows the part verdict, the
// characteristics (failed first), the defects, a 2D plot of each plan
// section (core/report/html_section_plot.h), the histogram, the
// statistics (always over all points, from the report), the settings and
// each viewpoint's calibration status.
//
// Everything is inline: three.js and the viewer as ES modules from data:
// URLs behind an import map, the report's data as JSON that cannot end its
// <script> element, the points as one base64 block (core/report/html_payload.h:
// at most PayloadSettings::max_points points, 9 bytes each before base64).
// Strings from outside are escaped (core/report/html_escape.h).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/report/html_payload.h"
#include "core/report/html_sections.h"
#include "core/types/point_cloud.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

struct HtmlReportInput {
  const InspectionReport* report = nullptr;  // with its plan, or an error map's alone
  const PointCloud* points_in_part = nullptr;
  const std::vector<float>* deviation_mm = nullptr;  // per point of points_in_part
  const TriangleMesh* mesh_in_part = nullptr;        // optional overlay
  HtmlReportContext context;
  PayloadSettings payload;
};

struct HtmlReportPage {
  std::string html;
  std::size_t shown_points = 0;
  double payload_seconds = 0;  // thinning and packing
};

// InvalidArgument naming what is missing (report, points, deviations,
// tolerance.band_mm, color_range_mm) or a size mismatch.
absl::StatusOr<HtmlReportPage> BuildHtmlReport(const HtmlReportInput& input);

// BuildHtmlReport, then written atomically.
absl::Status WriteHtmlReport(const std::string& path, const HtmlReportInput& input);

}  // namespace surfinspect
