// The HTML report's section plots: one inline SVG per section of the report
// (core/report/section_plot.h draws it; this file writes it as SVG). Inside
// the SVG's drawing group the coordinates are the plot's, mm in the plane
// (y up, flipped by the group's transform), so a reader of the page finds a
// whisker's foot and tip at (x1, y1) and (x2, y2) of its <line
// class="whisker">. Strings from the report are escaped.
#pragma once

#include <string>

#include "core/pipeline/inspection_report.h"
#include "core/report/deviation_palette.h"

namespace surfinspect {

// One <figure class="section"> per section: the title, the plot (the band
// as one <path class="band">, each nominal polyline as a <polyline
// class="nominal">, each whisker as a <line class="whisker"> in the
// palette's colour) and the caption with the exaggeration. "" when the
// report has no sections.
std::string SectionPlotsHtml(const InspectionReport& report, const DeviationPalette& palette);

}  // namespace surfinspect
