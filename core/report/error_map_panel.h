// The side panel of the error-map picture (paper Fig. 11): the verdict and
// figures, a colour bar with mm labels at +-range, +-tolerance and 0 whose
// tolerance band is bracketed, and the histogram on the same vertical
// deviation axis. Bar lengths follow log10(1 + count), so one bin holding
// 99% of the points leaves the others visible (every non-empty bin is at
// least 2 px long), and dashed lines mark +-tolerance across it.
#pragma once

#include <cstdint>

#include "core/errormap/error_map.h"
#include "core/io/png_image.h"

namespace surfinspect {

inline constexpr int kPanelWidth = 310;  // px
inline constexpr Rgb kPanelInk{0, 0, 0};

// Where the panel's parts lie, in image pixels.
struct PanelLayout {
  int x0 = 0;                 // left edge of the panel
  int top = 0, bottom = 0;    // the deviation axis: +range at top, -range at bottom
  int bar_x = 0, bar_w = 22;  // the colour bar
  int bracket_x = 0;          // the 2 px band bracket left of the bar
  int hist_x = 0, hist_w = 0;
  double range_mm = 1;
  // Pixel row of deviation `d` (mm) on the shared axis.
  int YOf(double d) const;
};

PanelLayout MakePanelLayout(int x0, uint32_t image_height, double range_mm);

// log10(1 + count) / log10(1 + peak): a histogram bar's share of the full
// length; 0 for an empty bin.
double LogBarFraction(std::size_t count, std::size_t peak);
// Length in px of a histogram bar holding `count` of a largest bin `peak`.
int HistogramBarLength(std::size_t count, std::size_t peak, int hist_w);

// Draws the panel into `img` (which must be at least x0 + kPanelWidth wide).
void DrawErrorMapPanel(RgbImage& img, const PanelLayout& layout, const ErrorMapResult& result,
                       bool pass);

}  // namespace surfinspect
