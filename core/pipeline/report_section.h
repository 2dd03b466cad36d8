// A plan section as report.json carries it (the "sections" list of
// core/pipeline/inspection_report.h): the section's name, its plane, the band
// it is judged against, the nominal curve and the whiskers, so that a reader
// (the HTML and PDF reports) can draw it without the CAD mesh. The verdict,
// point count and statistics stay in the section's characteristic (type
// "section", same name).
//
// Millimetres, part frame. Every number is rounded to 3 decimals when the
// report is made (positions and deviations to 1 um, unit vectors to 0.001,
// about 0.06 degrees), so the up to 400 whiskers of a section keep
// report.json short; the codec itself is exact. The curve and the whiskers
// are stored as flat x, y, z columns for the same reason.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "core/plan/inspection_plan.h"
#include "core/plan/plan_evaluation.h"

namespace surfinspect {

// One chained polyline of the nominal curve: x, y, z of each vertex in turn.
struct ReportPolyline {
  std::vector<double> xyz_mm;
  std::size_t size() const { return xyz_mm.size() / 3; }
  Eigen::Vector3d vertex(std::size_t i) const {
    return {xyz_mm[3 * i], xyz_mm[3 * i + 1], xyz_mm[3 * i + 2]};
  }
};

// The whiskers as columns: whisker i starts at its closest CAD point
// at(i) and shows its signed deviation along direction(i), the curve's unit
// normal in the plane (+ above the CAD surface).
struct ReportWhiskers {
  std::vector<double> at_mm;      // x, y, z per whisker
  std::vector<double> direction;  // x, y, z per whisker
  std::vector<double> deviation_mm;
  std::size_t size() const { return deviation_mm.size(); }
  Eigen::Vector3d at(std::size_t i) const {
    return {at_mm[3 * i], at_mm[3 * i + 1], at_mm[3 * i + 2]};
  }
  Eigen::Vector3d dir(std::size_t i) const {
    return {direction[3 * i], direction[3 * i + 1], direction[3 * i + 2]};
  }
};

struct ReportSection {
  std::string name;
  // The plan's plane: its point and unit normal.
  Eigen::Vector3d point_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  ToleranceBand tolerance{NAN, NAN};  // the section's band; NaN when not said
  std::vector<ReportPolyline> polylines;
  ReportWhiskers whiskers;
};

// One ReportSection per cut of `outcome`, in plan order: cut k is the k-th
// characteristic of type section (name and band), rounded as above.
std::vector<ReportSection> ReportSectionsOf(const PlanOutcome& outcome);

// DataLoss naming the field (report.sections[k].polylines[j].xyz_mm,
// report.sections[k].whiskers) when a decoded section's columns are not
// whole x, y, z triples or the whisker columns differ in length.
absl::Status CheckReportSections(const std::vector<ReportSection>& sections);

// A tolerance band's fields, as every part of the report writes them
// (core/types/json_fields.h).
template <typename V, typename R>
void VisitBand(V& v, R& band) {
  v("lower", band.lower_mm);
  v("upper", band.upper_mm);
}

template <typename V, typename R>
void VisitReportSection(V& v, R& s) {
  v.Require("name");
  v("name", s.name);
  v("point_mm", s.point_mm);
  v("normal", s.normal);
  v.Object("tolerance_mm", s.tolerance, [](auto& w, auto& b) { VisitBand(w, b); });
  v.List("polylines", s.polylines, [](auto& w, auto& line) { w("xyz_mm", line.xyz_mm); });
  v.Object("whiskers", s.whiskers, [](auto& w, auto& c) {
    w("at_mm", c.at_mm);
    w("direction", c.direction);
    w("deviation_mm", c.deviation_mm);
  });
}

// The report's "sections" list. Only a plan with sections writes the key,
// so the reports of other plans keep their bytes.
template <typename V, typename L>
void VisitReportSections(V& v, L& sections) {
  if (V::kReads || !sections.empty())
    v.List("sections", sections, [](auto& w, auto& s) { VisitReportSection(w, s); });
}

}  // namespace surfinspect
