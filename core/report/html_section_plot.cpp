#include "core/report/html_section_plot.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/report/html_escape.h"
#include "core/report/section_plot.h"

namespace surfinspect {
namespace {

constexpr double kWidthPx = 420, kMinHeightPx = 90, kMaxHeightPx = 420;

// Lines keep their pixel width whatever the plot's scale in mm.
constexpr char kStyle[] =
    "<style>.section-plot line,.section-plot polyline,.section-plot path"
    "{vector-effect:non-scaling-stroke;fill:none}.section-plot{max-width:100%}</style>\n";

std::string Hex(Rgb c) { return absl::StrFormat("#%02x%02x%02x", c.r, c.g, c.b); }

std::string Xy(const Eigen::Vector2d& p) { return absl::StrFormat("%.4f,%.4f", p.x(), p.y()); }

// The plot in its own mm, with a margin of 4% of its size around it.
std::string PlotSvg(const SectionPlot& plot) {
  if (plot.empty()) return "<p class=\"none\">nothing to draw: the cut is empty</p>\n";
  const Eigen::Vector2d size = (plot.max - plot.min).cwiseMax(1e-3);
  const double margin = 0.04 * size.maxCoeff();
  const Eigen::Vector2d lo = plot.min.array() - margin, span = size.array() + 2 * margin;
  const double height = std::clamp(kWidthPx * span.y() / span.x(), kMinHeightPx, kMaxHeightPx);
  // y up: the group flips y, so the viewBox spans -max.y .. -min.y.
  std::string out = absl::StrFormat(
      "<svg class=\"section-plot\" viewBox=\"%.4f %.4f %.4f %.4f\" width=\"%.0f\" "
      "height=\"%.0f\" role=\"img\">\n<g transform=\"scale(1,-1)\">\n",
      lo.x(), -(lo.y() + span.y()), span.x(), span.y(), kWidthPx, height);
  if (!plot.band.empty()) {
    std::string d;
    for (const SectionPlot::Bar& b : plot.band)
      absl::StrAppend(&d, "M", Xy(b.lower), "L", Xy(b.upper));
    absl::StrAppend(&out, "<path class=\"band\" stroke=\"#bfe3bf\" stroke-width=\"4\" d=\"", d,
                    "\"/>\n");
  }
  for (const auto& line : plot.curve) {
    std::string points;
    for (const Eigen::Vector2d& p : line)
      absl::StrAppend(&points, points.empty() ? "" : " ", Xy(p));
    absl::StrAppend(&out,
                    "<polyline class=\"nominal\" stroke=\"#222\" stroke-width=\"1.5\" "
                    "points=\"",
                    points, "\"/>\n");
  }
  for (const SectionPlot::Whisker& w : plot.whiskers)
    absl::StrAppendFormat(&out,
                          "<line class=\"whisker\" x1=\"%.4f\" y1=\"%.4f\" x2=\"%.4f\" "
                          "y2=\"%.4f\" stroke=\"%s\" stroke-width=\"1\"/>\n",
                          w.foot.x(), w.foot.y(), w.tip.x(), w.tip.y(), Hex(w.color));
  return out + "</g>\n</svg>\n";
}

}  // namespace

std::string SectionPlotsHtml(const InspectionReport& report, const DeviationPalette& palette) {
  if (report.sections.empty()) return "";
  std::string out = kStyle;
  for (const ReportSection& s : report.sections) {
    const SectionPlot plot = MakeSectionPlot(s, palette);
    absl::StrAppend(&out, "<figure class=\"section\" data-section=\"", HtmlEscape(s.name),
                    "\" data-exaggeration=\"", absl::StrFormat("%g", plot.exaggeration),
                    "\">\n<figcaption class=\"title\">", HtmlEscape(SectionPlotTitle(report, s)),
                    "</figcaption>\n", PlotSvg(plot), "<p class=\"caption\">",
                    HtmlEscape(SectionPlotCaption(s, plot)), "</p>\n</figure>\n");
  }
  return out;
}

}  // namespace surfinspect
