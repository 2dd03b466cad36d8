#include "core/report/html_histogram.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/report/html_escape.h"

namespace surfinspect {
namespace {

constexpr double kWidth = 420, kHeight = 190, kLeft = 34, kBottom = 22, kTop = 16;

std::string Hex(Rgb c) { return absl::StrFormat("#%02x%02x%02x", c.r, c.g, c.b); }

}  // namespace

std::string HistogramSvg(const Histogram& h, const DeviationPalette& palette) {
  const std::vector<double> counts(h.counts.begin(), h.counts.end());
  const double lo = std::isfinite(h.min_mm) ? h.min_mm : 0.0;
  const double hi = std::isfinite(h.max_mm) ? h.max_mm : 0.0;
  if (counts.empty() || !(hi > lo)) return "<p id=\"histogram\" class=\"none\">no histogram</p>\n";
  double top = 0;
  for (double c : counts) top = std::max(top, std::log10(1 + c));
  if (!(top > 0)) top = 1;
  const double plot_w = kWidth - kLeft - 4, plot_h = kHeight - kBottom - kTop;
  const auto x_of = [&](double mm) { return kLeft + (mm - lo) / (hi - lo) * plot_w; };
  std::string out = absl::StrFormat(
      "<svg id=\"histogram\" viewBox=\"0 0 %.0f %.0f\" role=\"img\" "
      "aria-label=\"deviation histogram, log count axis\">\n",
      kWidth, kHeight);
  const double tol = palette.tolerance_mm;
  const double band_lo = std::max(lo, -tol), band_hi = std::min(hi, tol);
  if (band_hi > band_lo)
    absl::StrAppendFormat(&out,
                          "<rect class=\"band\" x=\"%.2f\" y=\"%.2f\" width=\"%.2f\" "
                          "height=\"%.2f\" fill=\"#dfe\" />\n",
                          x_of(band_lo), kTop, x_of(band_hi) - x_of(band_lo), plot_h);
  const double bin = (hi - lo) / counts.size();
  for (std::size_t i = 0; i < counts.size(); ++i) {
    const double bar = std::log10(1 + counts[i]) / top * plot_h;
    const float centre = static_cast<float>(lo + (i + 0.5) * bin);
    absl::StrAppendFormat(&out,
                          "<rect x=\"%.2f\" y=\"%.2f\" width=\"%.2f\" height=\"%.2f\" fill=\"%s\">"
                          "<title>%.4f..%.4f mm: %.0f</title></rect>\n",
                          x_of(lo + i * bin), kTop + plot_h - bar,
                          std::max(0.5, plot_w / counts.size() - 0.5), bar,
                          Hex(palette.colors[PaletteIndex(palette, centre)]), lo + i * bin,
                          lo + (i + 1) * bin, counts[i]);
  }
  for (double mm : {lo, -tol, 0.0, tol, hi}) {
    if (mm < lo || mm > hi) continue;
    absl::StrAppendFormat(&out,
                          "<line x1=\"%.2f\" x2=\"%.2f\" y1=\"%.2f\" y2=\"%.2f\" stroke=\"#555\"/>"
                          "<text x=\"%.2f\" y=\"%.2f\" text-anchor=\"middle\">%g</text>\n",
                          x_of(mm), x_of(mm), kTop + plot_h, kTop + plot_h + 4, x_of(mm),
                          kHeight - 6, mm);
  }
  absl::StrAppendFormat(&out,
                        "<text x=\"2\" y=\"%.2f\">log</text>"
                        "<text x=\"%.2f\" y=\"%.2f\" text-anchor=\"end\">tallest bin %.0f; "
                        "below the range %s, above %s</text>\n</svg>\n",
                        kTop + plot_h / 2, kWidth - 4, kTop - 5, std::pow(10, top) - 1,
                        absl::StrCat(h.below_range), absl::StrCat(h.above_range));
  return out;
}

}  // namespace surfinspect
