// A plan section as a 2D plot, the drawing that the HTML report (inline SVG,
// core/report/html_section_plot.h) and the PDF report (a page of sections)
// both render, so the two show the same figure:
//
//  * the plane's 2D basis: `up` is the first of the part's z, y, x axes that
//    makes at least 30 degrees with the normal, with the normal's part
//    removed; `right` = up x normal, so the plot is the plane seen from the
//    side its normal points to (z stays up for any vertical plane);
//  * coordinates are mm in the plane from the section's point_mm: a part
//    point p is at ((p - point_mm) . right, (p - point_mm) . up);
//  * the nominal curve: the report's polylines;
//  * each whisker from its foot `at` to at + k * deviation * direction,
//    coloured by the report's deviation palette (core/report/deviation_palette.h);
//  * the band as a bar at each whisker, from at + k * lower * direction to
//    at + k * upper * direction: a whisker whose tip leaves its bar is out of
//    the band. Where no point was measured there is no bar;
//  * k, the exaggeration, makes the band's width about 5% of the curve's
//    extent: 0.05 * extent / (upper - lower), rounded down to 1, 2 or 5 times
//    a power of ten so that it reads easily (the widest whisker pair stands
//    in for a band that is not said). k is printed in the caption.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/pipeline/inspection_report.h"
#include "core/report/deviation_palette.h"

namespace surfinspect {

struct SectionPlot {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // the section's point_mm
  Eigen::Vector3d right = Eigen::Vector3d::UnitY(), up = Eigen::Vector3d::UnitZ();
  double exaggeration = 1;  // k
  std::vector<std::vector<Eigen::Vector2d>> curve;
  struct Whisker {
    Eigen::Vector2d foot = Eigen::Vector2d::Zero(), tip = Eigen::Vector2d::Zero();
    double deviation_mm = 0;
    Rgb color;
  };
  std::vector<Whisker> whiskers;
  struct Bar {
    Eigen::Vector2d lower = Eigen::Vector2d::Zero(), upper = Eigen::Vector2d::Zero();
  };
  std::vector<Bar> band;  // one per whisker when the band is known
  // Everything drawn; empty (min > max) when nothing is.
  Eigen::Vector2d min = Eigen::Vector2d::Constant(INFINITY);
  Eigen::Vector2d max = Eigen::Vector2d::Constant(-INFINITY);
  bool empty() const { return !(min.x() <= max.x()); }
  Eigen::Vector2d Project(const Eigen::Vector3d& p) const {
    return {(p - origin).dot(right), (p - origin).dot(up)};
  }
};

// The plot of one section of the report; a section without a normal (an
// empty cut) gives an empty plot.
SectionPlot MakeSectionPlot(const ReportSection& section, const DeviationPalette& palette);

// The texts around the plot, formatted once for both reports. The title:
// name, verdict, points and min/max/mean from the section's characteristic
// (type "section", same name) when the report has it.
std::string SectionPlotTitle(const InspectionReport& report, const ReportSection& section);
// "whiskers x 50, band -0.150..+0.150 mm, view along -x".
std::string SectionPlotCaption(const ReportSection& section, const SectionPlot& plot);

}  // namespace surfinspect
