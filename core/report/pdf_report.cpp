#include "core/report/pdf_report.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "core/errormap/deviation_color.h"
#include "core/io/atomic_file.h"
#include "core/report/error_map_panel.h"
#include "core/report/error_map_png.h"
#include "core/report/pdf_canvas.h"
#include "core/report/report_content.h"
#include "core/report/section_plot.h"
#include "core/types/status_macros.h"
#include "core/types/transform.h"

#ifndef SURFINSPECT_VERSION
#define SURFINSPECT_VERSION "unknown"
#endif

namespace surfinspect {
namespace {

using Font = PdfCanvas::Font;
constexpr double kLeft = 40, kRight = 555, kWidth = kRight - kLeft;
constexpr double kTop = 36, kBottom = 800;
constexpr Rgb kPassGreen{0, 130, 0}, kFailRed{190, 0, 0}, kGrey{110, 110, 110};
constexpr Rgb kWhite{255, 255, 255}, kInk{0, 0, 0}, kFailedRow{255, 228, 228};

// The page being filled: breaks to a new page (with the footer) when a
// block does not fit.
struct Pages {
  PdfCanvas& canvas;
  std::string footer;
  double y = kTop;
  void Footer() {
    canvas.Text(kLeft, kBottom + 14, absl::StrCat(footer, " \xC2\xB7 page ", canvas.page()),
                {7, false, kGrey}, kWidth);
  }
  void Need(double h) {
    if (y + h <= kBottom) return;
    Break();
  }
  void Break() {
    canvas.NewPage();
    Footer();
    y = kTop;
  }
};

void DrawHeader(Pages& p, const PdfReportInput& in, const ReportContent& c) {
  PdfCanvas& cv = p.canvas;
  p.y += cv.Text(kLeft, p.y, "Inspection report", {15, true}) + 4;
  const std::pair<const char*, std::string> fields[] = {
      {"Part", in.part_id},
      {"Time", in.time_utc.empty()
                   ? absl::FormatTime("%Y-%m-%d %H:%M:%S UTC", absl::Now(), absl::UTCTimeZone())
                   : in.time_utc},
      {"Cell", in.cell.empty() ? "-" : in.cell},
      {"Software", SoftwareVersion()}};
  for (int row = 0; row < 2; ++row) {
    double h = 0;
    for (int col = 0; col < 2; ++col) {
      const auto& [label, value] = fields[row * 2 + col];
      const double x = kLeft + col * kWidth / 2;
      cv.Text(x, p.y, label, {9, true});
      h = std::max(h, cv.Text(x + 55, p.y, value, {9}, kWidth / 2 - 60));
    }
    p.y += h + 2;
  }
  p.y += 6;
  const double banner = 34;
  cv.Rect(kLeft, p.y, kWidth, banner, c.pass ? kPassGreen : kFailRed);
  cv.Text(kLeft + 10, p.y + 5, c.pass ? "PASS" : "FAIL", {18, true, kWhite});
  cv.Text(kLeft + 90, p.y + 4, absl::StrCat("part verdict: ", c.verdict), {9, true, kWhite});
  cv.Text(kLeft + 90, p.y + 17, absl::StrCat("all matched points: ", c.reason),
          {7.5, false, kWhite}, kWidth - 100);
  p.y += banner + 10;
}

// The rasters of the map: for a merged cloud the top view (along -z), the
// front view (along +y: x to the right, z up; drawn as the renderer's view
// along -x of the cloud turned by +90 deg about z, so digits stay upright)
// and the side view (along -x: y to the right, z up); for an organized
// cloud its sensor grid.
absl::StatusOr<std::vector<std::pair<std::string, RgbImage>>> MapViews(const PdfReportInput& in,
                                                                       const ReportContent& c) {
  ErrorMapResult view;
  view.deviation_mm = *in.deviation_mm;
  view.tolerance_mm = c.tolerance_mm;
  view.color_range_mm = c.color_range_mm;
  ErrorMapPngOptions options;
  options.defects = &c.defect_marks;
  const PointCloud& pts = *in.points_in_part;
  std::vector<std::pair<std::string, RgbImage>> out;
  auto add = [&](const std::string& caption, const PointCloud& cloud, int axis) -> absl::Status {
    options.view_axis = axis;
    ASSIGN_OR_RETURN(auto map, RenderErrorMapView(cloud, view, ComputeBounds(cloud), options));
    out.emplace_back(caption, std::move(map));
    return absl::OkStatus();
  };
  if (pts.organized()) {
    options.max_map_pixels = 1000;
    RETURN_IF_ERROR(add("sensor grid (single view)", pts, -1));
    return out;
  }
  options.max_map_pixels = 900;
  RETURN_IF_ERROR(add("top: view along -z", pts, 2));
  // (x, y, z) -> (-y, x, z): depth -y (nearest the viewer at -y wins), right x, up z.
  const Eigen::Isometry3d turn(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  std::vector<Defect> turned = c.defect_marks;
  for (Defect& d : turned) d.centroid_mm = turn * d.centroid_mm;
  options.defects = &turned;
  RETURN_IF_ERROR(add("front: view along +y", TransformCloud(pts, turn), 0));
  options.defects = &c.defect_marks;
  RETURN_IF_ERROR(add("side: view along -x", pts, 0));
  return out;
}

// The views stacked in the box (x, y, w, h), each as wide as the box allows
// and all shrunk by one factor when their heights do not fit.
absl::Status DrawMaps(PdfCanvas& cv, const PdfReportInput& in, const ReportContent& c, double x,
                      double y, double w, double h) {
  ASSIGN_OR_RETURN(auto views, MapViews(in, c));
  constexpr double kCaption = 11, kGap = 4;
  double natural = 0;
  for (const auto& [caption, map] : views) natural += w * map.height / map.width;
  const double room = h - views.size() * (kCaption + kGap);
  const double shrink = std::min(1.0, room / natural);
  for (const auto& [caption, map] : views) {
    cv.Text(x, y, caption, {7.5, false, kGrey});
    const double iw = w * shrink, ih = iw * map.height / map.width;
    cv.Image(map, x + (w - iw) / 2, y + kCaption, iw, ih);
    y += kCaption + ih + kGap;
  }
  return absl::OkStatus();
}

// Colour bar (tolerance band bracketed on its left) and the log-count
// histogram on the same vertical deviation axis, +range at `top`.
void DrawLegend(PdfCanvas& cv, const ReportContent& c, double x, double top, double bottom) {
  const double range = c.color_range_mm, tol = c.tolerance_mm;
  auto y_of = [&](double d) { return top + (range - d) / (2 * range) * (bottom - top); };
  auto color = [&](double d) { return DeviationColor(d, tol, range); };
  const double bar_x = x + 8, bar_w = 12;
  cv.Text(bar_x, top - 24, "mm", {7.5, true});
  cv.Rect(bar_x, top - 7, bar_w, 5, color(2 * range));
  cv.Rect(bar_x, bottom + 2, bar_w, 5, color(-2 * range));
  for (double yy = top; yy < bottom; yy += 1)
    cv.Rect(bar_x, yy, bar_w, std::min(1.0, bottom - yy) + 0.05,
            color(range - (yy - top + 0.5) / (bottom - top) * 2 * range));
  std::vector<double> ticks = {range, 0.0, -range};
  if (tol < range && y_of(tol) - y_of(range) > 10 && y_of(0) - y_of(tol) > 10)
    ticks.insert(ticks.end(), {tol, -tol});
  for (double t : ticks) {
    cv.Line(bar_x + bar_w, y_of(t), bar_x + bar_w + 3, y_of(t), 0.6, kInk);
    cv.Text(bar_x + bar_w + 4, y_of(t) - 4.5, FormatMm(t), {6.5});
  }
  const double hi = y_of(std::min(tol, range)), lo = y_of(-std::min(tol, range));
  cv.Line(x + 4, hi, x + 4, lo, 1.2, kInk);
  cv.Line(x + 4, hi, bar_x, hi, 0.8, kInk);
  cv.Line(x + 4, lo, bar_x, lo, 0.8, kInk);
  cv.Rect(bar_x, bottom + 12, bar_w, 5, kUnmatchedGrey);
  cv.Text(bar_x + bar_w + 3, bottom + 10, "unmatched", {6});

  const Histogram& h = c.histogram;
  const double hx = x + 62, hw = kRight - hx;
  const std::size_t peak =
      h.counts.empty() ? 0 : *std::max_element(h.counts.begin(), h.counts.end());
  cv.Line(hx, top, hx, bottom, 0.6, kInk);
  for (std::size_t k = 0; k < h.counts.size() && peak > 0; ++k) {
    const double lo_mm = h.min_mm + k * h.bin_width_mm(), hi_mm = lo_mm + h.bin_width_mm();
    const double len = h.counts[k] ? std::max(1.0, LogBarFraction(h.counts[k], peak) * hw) : 0;
    cv.Rect(hx, y_of(hi_mm), len, std::max(0.5, y_of(lo_mm) - y_of(hi_mm)),
            color(0.5 * (lo_mm + hi_mm)));
  }
  if (tol < range)
    for (double t : {tol, -tol}) cv.Line(hx, y_of(t), kRight, y_of(t), 0.6, kInk, true);
  cv.Text(hx, top - 24, absl::StrCat("log count (max ", peak, ")"), {6.5}, hw);
  cv.Text(hx, bottom + 10, "histogram", {6});
}

void DrawStatistics(Pages& p, const ReportContent& c) {
  const double col = kWidth / 4;
  p.Need(14 + 12 * ((c.statistics.size() + 3) / 4));
  p.y += p.canvas.Text(kLeft, p.y, "Statistics (matched points, mm)", {10, true}) + 3;
  for (std::size_t i = 0; i < c.statistics.size(); i += 4) {
    for (std::size_t j = i; j < std::min(i + 4, c.statistics.size()); ++j) {
      const double x = kLeft + (j - i) * col;
      p.canvas.Text(x, p.y, c.statistics[j].first, {8, false, kGrey});
      p.canvas.Text(x + 58, p.y, c.statistics[j].second, {8}, col - 60);
    }
    p.y += 12;
  }
  p.y += 8;
}

// A table with its header row repeated on every page; failed rows tinted.
void DrawTable(Pages& p, const std::string& title, const ReportTable& t,
               const std::vector<double>& widths) {
  const Font cell{7.5}, head{7.5, true};
  auto row_height = [&](const std::vector<std::string>& row, const Font& f) {
    double h = 0;
    for (std::size_t k = 0; k < row.size(); ++k)
      h = std::max(h, p.canvas.TextHeight(row[k], f, widths[k] - 4));
    return h + 4;
  };
  auto draw_row = [&](const std::vector<std::string>& row, const Font& f, double h, Rgb bg) {
    p.canvas.Rect(kLeft, p.y, kWidth, h, bg);
    double x = kLeft;
    for (std::size_t k = 0; k < row.size(); ++k) {
      p.canvas.Text(x + 2, p.y + 2, row[k], f, widths[k] - 4);
      x += widths[k];
    }
    p.y += h;
  };
  const double head_h = row_height(t.header, head);
  p.Need(18 + head_h + 14);
  p.y += p.canvas.Text(kLeft, p.y, title, {10, true}) + 3;
  draw_row(t.header, head, head_h, {225, 225, 225});
  if (t.rows.empty()) p.y += p.canvas.Text(kLeft + 2, p.y + 2, "none", cell) + 4;
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    const double h = row_height(t.rows[i], cell);
    if (p.y + h > kBottom) {
      p.Need(kBottom);
      draw_row(t.header, head, head_h, {225, 225, 225});
    }
    draw_row(t.rows[i], cell, h, t.failed[i] ? kFailedRow : kWhite);
  }
  p.y += 12;
}

// How the scan was aligned: its lines, then the RPS references' table.
void DrawAlignment(Pages& p, const ReportContent& c) {
  if (c.alignment_lines.empty() && c.alignment.header.empty()) return;
  p.Need(60);
  p.y += p.canvas.Text(kLeft, p.y, "Alignment", {10, true}) + 3;
  for (const std::string& line : c.alignment_lines)
    p.y += p.canvas.Text(kLeft, p.y, line, {8}, kWidth) + 2;
  p.y += 6;
  if (!c.alignment.rows.empty())
    DrawTable(p, "Alignment references", c.alignment, {70, 40, 45, 120, 80, 80, 80});
}

// One section's plot (core/report/section_plot.h) scaled into the box (x,
// y, w, h), y up, with a thin frame: the band's bars, the nominal curve and
// the whiskers, as the HTML report draws them.
void DrawSectionPlot(PdfCanvas& cv, const SectionPlot& plot, double x, double y, double w,
                     double h) {
  const Rgb frame{200, 200, 200};
  cv.Line(x, y, x + w, y, 0.4, frame);
  cv.Line(x, y + h, x + w, y + h, 0.4, frame);
  cv.Line(x, y, x, y + h, 0.4, frame);
  cv.Line(x + w, y, x + w, y + h, 0.4, frame);
  if (plot.empty()) return;
  const Eigen::Vector2d size = (plot.max - plot.min).cwiseMax(1e-3);
  const double scale = 0.92 * std::min(w / size.x(), h / size.y());
  const Eigen::Vector2d centre = 0.5 * (plot.min + plot.max);
  auto line = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b, double width, Rgb color) {
    cv.Line(x + w / 2 + (a.x() - centre.x()) * scale, y + h / 2 - (a.y() - centre.y()) * scale,
            x + w / 2 + (b.x() - centre.x()) * scale, y + h / 2 - (b.y() - centre.y()) * scale,
            width, color);
  };
  for (const SectionPlot::Bar& b : plot.band) line(b.lower, b.upper, 2.5, {191, 227, 191});
  for (const auto& curve : plot.curve)
    for (std::size_t i = 0; i + 1 < curve.size(); ++i) line(curve[i], curve[i + 1], 0.9, kInk);
  for (const SectionPlot::Whisker& wh : plot.whiskers) line(wh.foot, wh.tip, 0.5, wh.color);
}

// The sections from a new page, six to a page (two across, three down),
// each with its title above and its caption (the exaggeration) below.
void DrawSections(Pages& p, const InspectionReport& report, const ReportContent& c) {
  if (report.sections.empty()) return;
  const DeviationPalette palette = MakeDeviationPalette(c.tolerance_mm, c.color_range_mm);
  constexpr int kAcross = 2, kPerPage = 6;
  constexpr double kHeading = 20, kGap = 12, kTitle = 22, kCaption = 20;
  const double cell_w = (kWidth - kGap) / kAcross;
  const double cell_h = (kBottom - kTop - kHeading) / (kPerPage / kAcross);
  for (std::size_t i = 0; i < report.sections.size(); ++i) {
    if (i % kPerPage == 0) {
      p.Break();
      p.y += p.canvas.Text(kLeft, p.y, "Sections (mm in the section plane)", {10, true}) + 6;
    }
    const ReportSection& s = report.sections[i];
    const SectionPlot plot = MakeSectionPlot(s, palette);
    const double x = kLeft + (i % kAcross) * (cell_w + kGap);
    const double y = p.y + ((i % kPerPage) / kAcross) * cell_h;
    p.canvas.Text(x, y, SectionPlotTitle(report, s), {7.5, true}, cell_w);
    DrawSectionPlot(p.canvas, plot, x, y + kTitle, cell_w, cell_h - kTitle - kCaption - 4);
    p.canvas.Text(x, y + cell_h - kCaption - 2, SectionPlotCaption(s, plot), {6.5, false, kGrey},
                  cell_w);
  }
}

}  // namespace

std::string SoftwareVersion() { return absl::StrCat("surfinspect ", SURFINSPECT_VERSION); }

absl::StatusOr<std::string> RenderPdfReport(const PdfReportInput& in) {
  if (!in.report || !in.points_in_part || !in.deviation_mm)
    return absl::InvalidArgumentError("pdf report: report, points and deviations are required");
  if (in.deviation_mm->size() != in.points_in_part->size())
    return absl::InvalidArgumentError(absl::StrCat("pdf report: ", in.points_in_part->size(),
                                                   " points but ", in.deviation_mm->size(),
                                                   " deviations"));
  ASSIGN_OR_RETURN(auto content, ReportContentFrom(*in.report));
  const ReportContent& c = content;
  ASSIGN_OR_RETURN(auto canvas,
                   PdfCanvas::Create(absl::StrCat("surfinspect report: ", in.part_id)));
  Pages p{*canvas, absl::StrCat(SoftwareVersion(), " \xC2\xB7 part ", in.part_id)};
  p.Footer();
  DrawHeader(p, in, c);
  const double map_h = 430, legend_x = kLeft + 385;
  RETURN_IF_ERROR(DrawMaps(p.canvas, in, c, kLeft, p.y, legend_x - kLeft - 10, map_h));
  DrawLegend(p.canvas, c, legend_x, p.y + 30, p.y + map_h - 30);
  p.y += map_h + 8;
  DrawStatistics(p, c);
  // One width per column of CharacteristicHeader(), kWidth in all.
  DrawTable(p, "Characteristics (failed first)", c.characteristics,
            {88, 32, 40, 78, 78, 40, 40, 42, 35, 42});
  DrawTable(p, "Defects", c.defects, {30, 32, 88, 45, 40, 45, 45, 45, 135});
  DrawAlignment(p, c);
  DrawSections(p, *in.report, c);
  return p.canvas.Finish();
}

absl::Status WritePdfReport(const std::string& path, const PdfReportInput& input) {
  ASSIGN_OR_RETURN(auto bytes, RenderPdfReport(input));
  return WriteStringAtomically(path, bytes);
}

}  // namespace surfinspect
