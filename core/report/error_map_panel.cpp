#include "core/report/error_map_panel.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/errormap/deviation_color.h"

namespace surfinspect {
namespace {

Rgb Color(const ErrorMapResult& r, double d) {
  return DeviationColor(d, r.tolerance_mm, r.color_range_mm);
}

std::string Label(double v, double range) {
  const int decimals = range >= 10 ? 1 : range >= 1 ? 2 : range >= 0.01 ? 3 : 4;
  return absl::StrFormat("%+.*f", decimals, v);
}

void DrawFigures(RgbImage& img, int x0, const ErrorMapResult& r, bool pass) {
  const Verdict& v = r.verdict;
  const double range = r.color_range_mm;
  img.DrawText(x0 + 10, 10, pass ? "pass" : "fail", pass ? Rgb{0, 140, 0} : Rgb{200, 0, 0}, 3);
  img.DrawText(x0 + 10, 40, absl::StrCat("tol +-", Label(r.tolerance_mm, range).substr(1), " mm"),
               kPanelInk, 2);
  img.DrawText(x0 + 10, 58,
               absl::StrFormat("in tol %.2f%%",
                               100 * (std::isnan(v.fraction_within) ? 0 : v.fraction_within)),
               kPanelInk, 2);
  img.DrawText(x0 + 10, 76, absl::StrCat("rms ", Label(r.stats.rms_mm, range).substr(1), " mm"),
               kPanelInk, 2);
  img.DrawText(x0 + 10, 94, absl::StrCat("n ", r.stats.matched, "/", r.stats.valid), kPanelInk, 2);
}

// The colour bar, its ticks, and a bracket from +tol to -tol on its left.
void DrawColourBar(RgbImage& img, const PanelLayout& l, const ErrorMapResult& r) {
  const double range = l.range_mm, span = l.bottom - l.top;
  const int bar_x = l.bar_x;
  img.DrawText(bar_x, l.top - 26, "mm", kPanelInk, 2);
  img.FillRect(bar_x, l.top - 8, l.bar_w, 6, Color(r, 2 * range));  // beyond the scale
  img.FillRect(bar_x, l.bottom + 2, l.bar_w, 6, Color(r, -2 * range));
  for (int y = l.top; y < l.bottom; ++y)
    img.FillRect(bar_x, y, l.bar_w, 1, Color(r, range - (y - l.top + 0.5) / span * 2 * range));
  std::vector<double> ticks = {range, 0.0, -range};
  if (r.tolerance_mm < range && l.YOf(r.tolerance_mm) - l.YOf(range) > 16 &&
      l.YOf(0) - l.YOf(r.tolerance_mm) > 16)
    ticks.insert(ticks.end(), {r.tolerance_mm, -r.tolerance_mm});
  for (double t : ticks) {
    const int y = l.YOf(t);
    img.FillRect(bar_x + l.bar_w, y, 6, 1, kPanelInk);
    img.DrawText(bar_x + l.bar_w + 8, y - 7, Label(t, range), kPanelInk, 2);
  }
  const int y_hi = l.YOf(std::min(r.tolerance_mm, range));
  const int y_lo = l.YOf(-std::min(r.tolerance_mm, range));
  img.FillRect(l.bracket_x, y_hi, 2, y_lo - y_hi + 1, kPanelInk);
  img.FillRect(l.bracket_x, y_hi, bar_x - l.bracket_x, 1, kPanelInk);
  img.FillRect(l.bracket_x, y_lo, bar_x - l.bracket_x, 1, kPanelInk);
}

void DrawHistogram(RgbImage& img, const PanelLayout& l, const ErrorMapResult& r) {
  const Histogram& h = r.histogram;
  const std::size_t peak =
      h.counts.empty() ? 0 : *std::max_element(h.counts.begin(), h.counts.end());
  img.FillRect(l.hist_x - 1, l.top, 1, l.bottom - l.top, kPanelInk);  // the axis
  for (std::size_t k = 0; k < h.counts.size() && peak > 0; ++k) {
    const double lo = h.min_mm + k * h.bin_width_mm(), hi = lo + h.bin_width_mm();
    const int y_top = l.YOf(hi), y_bottom = std::max(l.YOf(lo), y_top + 1);
    img.FillRect(l.hist_x, y_top, HistogramBarLength(h.counts[k], peak, l.hist_w), y_bottom - y_top,
                 Color(r, 0.5 * (lo + hi)));
  }
  img.DrawText(l.hist_x, l.bottom + 12, "log n", kPanelInk, 2);
  if (!(r.tolerance_mm < l.range_mm)) return;
  for (double t : {r.tolerance_mm, -r.tolerance_mm})
    for (int x = l.hist_x; x < l.hist_x + l.hist_w; x += 6)
      img.FillRect(x, l.YOf(t), 3, 1, kPanelInk);
}

}  // namespace

int PanelLayout::YOf(double d) const {
  const double span = bottom - top;
  return top + static_cast<int>(std::lround((range_mm - d) / (2 * range_mm) * span));
}

PanelLayout MakePanelLayout(int x0, uint32_t image_height, double range_mm) {
  PanelLayout l;
  l.x0 = x0;
  l.top = 140;
  l.bottom = static_cast<int>(image_height) - 40;
  l.bar_x = x0 + 14;
  l.bracket_x = x0 + 6;
  l.hist_x = x0 + 130;
  l.hist_w = kPanelWidth - 140;
  l.range_mm = range_mm;
  return l;
}

double LogBarFraction(std::size_t count, std::size_t peak) {
  if (count == 0 || peak == 0) return 0;
  return std::log10(1.0 + count) / std::log10(1.0 + peak);
}

int HistogramBarLength(std::size_t count, std::size_t peak, int hist_w) {
  if (count == 0 || peak == 0) return 0;
  return std::max(2, static_cast<int>(std::lround(LogBarFraction(count, peak) * hist_w)));
}

void DrawErrorMapPanel(RgbImage& img, const PanelLayout& layout, const ErrorMapResult& result,
                       bool pass) {
  DrawFigures(img, layout.x0, result, pass);
  DrawColourBar(img, layout, result);
  DrawHistogram(img, layout, result);
}

}  // namespace surfinspect
