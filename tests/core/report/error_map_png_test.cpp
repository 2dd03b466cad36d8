// The error-map PNG's panel, core/report/error_map_panel.cpp, read back
// from the encoded PNG with libpng's own decoder: the tolerance band is
// bracketed on the colour bar and dashed across the histogram, and the
// histogram's log count axis keeps small bins visible next to one holding
// 99% of the points.
#include "core/report/error_map_png.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/errormap/deviation_color.h"
#include "core/report/error_map_panel.h"
#include "tests/support/png_decode.h"

namespace surfinspect {
namespace {

constexpr Rgb kWhitePx{255, 255, 255}, kBlackPx{0, 0, 0};

// A 20 x 10 organized cloud (drawn 400 x 200) with a hand-made result:
// +-0.1 mm band, +-0.5 mm scale, 41 bins over [-0.5, 0.5).
struct Picture {
  PointCloud cloud;
  ErrorMapResult result;
};

Picture MakePicture(const std::vector<std::pair<int, std::size_t>>& bins) {
  Picture p;
  p.cloud.width = 20;
  p.cloud.height = 10;
  for (int i = 0; i < 200; ++i) {
    p.cloud.points.emplace_back(static_cast<float>(i % 20), static_cast<float>(i / 20), 0.f);
    p.result.deviation_mm.push_back(static_cast<float>((i % 20) - 10) * 0.05f);
  }
  p.result.tolerance_mm = 0.1;
  p.result.color_range_mm = 0.5;
  p.result.histogram.min_mm = -0.5;
  p.result.histogram.max_mm = 0.5;
  p.result.histogram.counts.assign(41, 0);
  for (const auto& [k, n] : bins) p.result.histogram.counts[k] = n;
  return p;
}

// Renders, encodes and decodes: the pixels a viewer of the PNG sees.
RgbImage Decoded(const Picture& p) {
  auto img = RenderErrorMap(p.cloud, p.result, ComputeBounds(p.cloud));
  EXPECT_TRUE(img.ok()) << img.status();
  auto bytes = EncodePng(*img);
  EXPECT_TRUE(bytes.ok());
  RgbImage out = testing::DecodePng(*bytes);
  EXPECT_EQ(out.width, img->width);
  return out;
}

PanelLayout LayoutOf(const RgbImage& img) {
  return MakePanelLayout(static_cast<int>(img.width) - kPanelWidth, img.height, 0.5);
}

TEST(ErrorMapPanel, ColourBarBracketsExactlyTheToleranceBand) {
  const RgbImage img = Decoded(MakePicture({{20, 10}}));
  ASSERT_GT(img.width, 0u);
  const PanelLayout l = LayoutOf(img);
  const int hi = l.YOf(0.1), lo = l.YOf(-0.1);
  // The oracle: +0.1 mm sits 40% of the way down the +-0.5 mm axis.
  EXPECT_EQ(hi, l.top + static_cast<int>(std::lround(0.4 * (l.bottom - l.top))));
  for (int x : {l.bracket_x, l.bracket_x + 1}) {
    for (int y = hi; y <= lo; ++y) EXPECT_EQ(img.at(x, y), kBlackPx) << x << "," << y;
    for (double d : {0.45, 0.2, -0.2, -0.45}) EXPECT_EQ(img.at(x, l.YOf(d)), kWhitePx) << d;
  }
  for (int x = l.bracket_x; x < l.bar_x; ++x) {
    EXPECT_EQ(img.at(x, hi), kBlackPx) << "upper end tick at x " << x;
    EXPECT_EQ(img.at(x, lo), kBlackPx) << "lower end tick at x " << x;
  }
  // The bar itself keeps its colours: green inside the bracket, not outside.
  const int y = l.YOf(0.05);
  const Rgb inside = img.at(l.bar_x + 5, y);
  EXPECT_EQ(inside, DeviationColor(0.5 - (y - l.top + 0.5) / (l.bottom - l.top), 0.1, 0.5))
      << "the colour at the row's centre";
  EXPECT_FALSE(img.at(l.bar_x + 5, l.YOf(0.3)) == inside);
}

TEST(ErrorMapPanel, LogAxisKeepsSmallBinsVisibleBesideA99PercentBin) {
  // 99000 of 99901 points in the centre bin.
  const std::vector<std::pair<int, std::size_t>> bins = {
      {20, 99000}, {10, 500}, {30, 400}, {35, 1}};
  const Picture p = MakePicture(bins);
  const RgbImage img = Decoded(p);
  ASSERT_GT(img.width, 0u);
  const PanelLayout l = LayoutOf(img);
  const Histogram& h = p.result.histogram;
  for (int k = 0; k < 41; ++k) {
    const double lo = h.min_mm + k * h.bin_width_mm(), hi = lo + h.bin_width_mm();
    const int y = (l.YOf(hi) + std::max(l.YOf(lo), l.YOf(hi) + 1) - 1) / 2;
    if (std::abs(y - l.YOf(0.1)) <= 1 || std::abs(y - l.YOf(-0.1)) <= 1) continue;  // dashes
    int len = 0;
    while (len < l.hist_w + 5 && !(img.at(l.hist_x + len, y) == kWhitePx)) ++len;
    EXPECT_EQ(len, HistogramBarLength(h.counts[k], 99000, l.hist_w)) << "bin " << k;
    if (h.counts[k] > 0) {
      EXPECT_EQ(img.at(l.hist_x, y), DeviationColor(0.5 * (lo + hi), 0.1, 0.5)) << "bin " << k;
    }
  }
  // A linear axis would draw 500 of 99000 as 0.86 px; the log axis over half the width.
  EXPECT_GT(HistogramBarLength(500, 99000, l.hist_w), l.hist_w / 2);
  EXPECT_GT(HistogramBarLength(400, 99000, l.hist_w), l.hist_w / 2);
  EXPECT_EQ(HistogramBarLength(1, 99000, l.hist_w), 10);  // log10 2 / log10 99001 * 170
  EXPECT_EQ(HistogramBarLength(99000, 99000, l.hist_w), l.hist_w);
}

TEST(ErrorMapPanel, DashedLinesMarkTheBandAcrossTheHistogram) {
  const RgbImage img = Decoded(MakePicture({{20, 1000}}));
  ASSERT_GT(img.width, 0u);
  const PanelLayout l = LayoutOf(img);
  for (double t : {0.1, -0.1}) {
    const int y = l.YOf(t);
    for (int x = l.hist_x; x < l.hist_x + l.hist_w; ++x)
      EXPECT_EQ(img.at(x, y), (x - l.hist_x) % 6 < 3 ? kBlackPx : kWhitePx) << t << " at " << x;
    EXPECT_EQ(img.at(l.hist_x + 1, y - 3), kWhitePx) << "one row only";
  }
}

TEST(ErrorMapPanel, BarLengthIsLogCountOverLogPeak) {
  EXPECT_EQ(HistogramBarLength(0, 100, 170), 0);
  EXPECT_EQ(HistogramBarLength(5, 0, 170), 0);
  EXPECT_DOUBLE_EQ(LogBarFraction(9, 99), 0.5);  // log10 10 / log10 100
  EXPECT_EQ(HistogramBarLength(9, 99, 170), 85);
  int previous = 0;
  for (std::size_t n = 1; n <= 1000000; n *= 10) {
    const int len = HistogramBarLength(n, 1000000, 170);
    EXPECT_GE(len, 2);
    EXPECT_GT(len, previous);
    previous = len;
  }
}

}  // namespace
}  // namespace surfinspect
