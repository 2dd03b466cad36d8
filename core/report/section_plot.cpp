#include "core/report/section_plot.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/report/report_content.h"

namespace surfinspect {
namespace {

// The in-plane basis of the header: up from the first of z, y, x at 30
// degrees or more from the normal (its in-plane part is then >= 0.5 long;
// one of the three always is, as some component of a unit normal is at most
// 1/sqrt(3)), right = up x normal.
void Basis(const Eigen::Vector3d& normal, SectionPlot& plot) {
  const Eigen::Vector3d n = normal.normalized();
  for (int axis : {2, 1, 0}) {
    const Eigen::Vector3d a = Eigen::Vector3d::Unit(axis);
    const Eigen::Vector3d in_plane = a - a.dot(n) * n;
    if (in_plane.norm() < 0.5) continue;
    plot.up = in_plane.normalized();
    plot.right = plot.up.cross(n);
    return;
  }
}

// 0.05 * extent / width rounded down to 1, 2 or 5 x 10^n; 1 when either is
// unknown. The 1e-9 keeps a ratio that is 5 x 10^n but for rounding from
// falling to 2 x 10^n (or 10^n to 5 x 10^(n-1)).
double Exaggeration(double extent_mm, double width_mm) {
  if (!(extent_mm > 0) || !(width_mm > 0) || !std::isfinite(extent_mm / width_mm)) return 1;
  const double raw = 0.05 * extent_mm / width_mm * (1 + 1e-9);
  const double decade = std::pow(10.0, std::floor(std::log10(raw)));
  const double mantissa = raw / decade;
  return (mantissa >= 5 ? 5 : mantissa >= 2 ? 2 : 1) * decade;
}

void Grow(SectionPlot& plot, const Eigen::Vector2d& p) {
  plot.min = plot.min.cwiseMin(p);
  plot.max = plot.max.cwiseMax(p);
}

// The extent of the curve (of the whiskers' feet without one), mm.
double CurveExtent(const SectionPlot& plot) {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(INFINITY), hi = -lo;
  for (const auto& line : plot.curve)
    for (const Eigen::Vector2d& p : line) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  if (plot.curve.empty())
    for (const SectionPlot::Whisker& w : plot.whiskers)
      lo = lo.cwiseMin(w.foot), hi = hi.cwiseMax(w.foot);
  return lo.x() <= hi.x() ? (hi - lo).maxCoeff() : 0.0;
}

bool Known(const ToleranceBand& band) {
  return std::isfinite(band.lower_mm) && std::isfinite(band.upper_mm) &&
         band.upper_mm > band.lower_mm;
}

// "+x" for an axis, else the vector to 2 decimals.
std::string Direction(const Eigen::Vector3d& v) {
  for (int k = 0; k < 3; ++k)
    if (std::abs(v[k]) > 0.9999)
      return absl::StrCat(v[k] > 0 ? "+" : "-", std::string(1, "xyz"[k]));
  return absl::StrFormat("(%.2f, %.2f, %.2f)", v.x(), v.y(), v.z());
}

}  // namespace

SectionPlot MakeSectionPlot(const ReportSection& s, const DeviationPalette& palette) {
  SectionPlot plot;
  if (!(s.normal.norm() > 0)) return plot;
  plot.origin = s.point_mm;
  Basis(s.normal, plot);
  for (const ReportPolyline& line : s.polylines) {
    std::vector<Eigen::Vector2d>& out = plot.curve.emplace_back();
    for (std::size_t i = 0; i < line.size(); ++i) out.push_back(plot.Project(line.vertex(i)));
  }
  const ReportWhiskers& w = s.whiskers;
  double largest = 0;
  for (std::size_t i = 0; i < w.size(); ++i) {
    largest = std::max(largest, std::abs(w.deviation_mm[i]));
    plot.whiskers.emplace_back().foot = plot.Project(w.at(i));
  }
  const bool band = Known(s.tolerance);
  plot.exaggeration = Exaggeration(
      CurveExtent(plot), band ? s.tolerance.upper_mm - s.tolerance.lower_mm : 2 * largest);
  const double k = plot.exaggeration;
  for (std::size_t i = 0; i < w.size(); ++i) {
    SectionPlot::Whisker& out = plot.whiskers[i];
    out.deviation_mm = w.deviation_mm[i];
    out.tip = plot.Project(w.at(i) + k * w.deviation_mm[i] * w.dir(i));
    out.color = palette.colors[PaletteIndex(palette, static_cast<float>(w.deviation_mm[i]))];
    Grow(plot, out.foot);
    Grow(plot, out.tip);
    if (!band) continue;
    plot.band.push_back({plot.Project(w.at(i) + k * s.tolerance.lower_mm * w.dir(i)),
                         plot.Project(w.at(i) + k * s.tolerance.upper_mm * w.dir(i))});
    Grow(plot, plot.band.back().lower);
    Grow(plot, plot.band.back().upper);
  }
  for (const auto& line : plot.curve)
    for (const Eigen::Vector2d& p : line) Grow(plot, p);
  return plot;
}

std::string SectionPlotTitle(const InspectionReport& report, const ReportSection& s) {
  for (const ReportCharacteristic& c : report.characteristics)
    if (c.type == "section" && c.name == s.name)
      return absl::StrCat(s.name, ": ", c.verdict, ", ", c.points, " points, min ",
                          FormatMm(c.min_mm), ", max ", FormatMm(c.max_mm), ", mean ",
                          FormatMm(c.mean_mm), " mm");
  return s.name;
}

std::string SectionPlotCaption(const ReportSection& s, const SectionPlot& plot) {
  std::string band = "band not said";
  if (Known(s.tolerance))
    band = absl::StrCat("band ", FormatMm(s.tolerance.lower_mm), "..",
                        FormatMm(s.tolerance.upper_mm), " mm");
  return absl::StrCat("whiskers x ", absl::StrFormat("%g", plot.exaggeration), ", ", band,
                      "; right ", Direction(plot.right), ", up ", Direction(plot.up));
}

}  // namespace surfinspect
