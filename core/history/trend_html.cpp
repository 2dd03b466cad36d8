#include "core/history/trend_html.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/report/deviation_palette.h"
#include "core/report/html_escape.h"
#include "core/report/html_payload.h"
#include "core/report/viewer_assets.h"
#include "core/report/viewer_page.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

constexpr int kW = 720, kH = 200, kPad = 40;

// `digits` after the point, with a sign when `sign`; a dash when not finite.
std::string Fmt(double v, int digits = 4, bool sign = false) {
  if (!std::isfinite(v)) return "&ndash;";
  return sign ? absl::StrFormat("%+.*f", digits, v) : absl::StrFormat("%.*f", digits, v);
}

// A chart of `y` against the part index with horizontal lines at `lines`
// (centre solid, limits dashed); `flagged` points are red.
std::string Chart(const std::string& label, const std::vector<double>& y,
                  const std::vector<double>& lines, const std::vector<bool>& flagged,
                  const std::optional<DriftLine>& drift) {
  double lo = *std::min_element(y.begin(), y.end()), hi = *std::max_element(y.begin(), y.end());
  for (double l : lines) lo = std::min(lo, l), hi = std::max(hi, l);
  if (!(hi > lo)) hi = lo + 1e-3;
  const double n = std::max<double>(1, y.size() - 1);
  auto X = [&](double i) { return kPad + i / n * (kW - 2 * kPad); };
  auto Y = [&](double v) { return kH - kPad / 2 - (v - lo) / (hi - lo) * (kH - kPad); };
  std::string svg = absl::StrFormat(
      "<svg width=\"%d\" height=\"%d\"><text x=\"4\" y=\"14\">%s</text>", kW, kH, label);
  for (std::size_t k = 0; k < lines.size(); ++k)
    absl::StrAppendFormat(&svg,
                          "<line x1=\"%d\" x2=\"%d\" y1=\"%.1f\" y2=\"%.1f\" stroke=\"#555\"%s/>"
                          "<text x=\"%d\" y=\"%.1f\" font-size=\"10\">%.4f</text>",
                          kPad, kW - kPad, Y(lines[k]), Y(lines[k]),
                          k == 0 ? "" : " stroke-dasharray=\"4 3\"", kW - kPad + 2, Y(lines[k]) + 3,
                          lines[k]);
  if (drift)
    absl::StrAppendFormat(
        &svg, "<line x1=\"%.1f\" x2=\"%.1f\" y1=\"%.1f\" y2=\"%.1f\" stroke=\"#c80\"/>", X(0), X(n),
        Y(drift->intercept_mm), Y(drift->intercept_mm + drift->slope_mm_per_part * n));
  std::string path;
  for (std::size_t i = 0; i < y.size(); ++i)
    absl::StrAppendFormat(&path, "%s%.1f,%.1f ", i == 0 ? "M" : "L", X(i), Y(y[i]));
  absl::StrAppend(&svg, "<path d=\"", path, "\" fill=\"none\" stroke=\"#248\"/>");
  for (std::size_t i = 0; i < y.size(); ++i)
    absl::StrAppendFormat(&svg, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"%d\" fill=\"%s\"/>", X(i),
                          Y(y[i]), flagged[i] ? 4 : 2, flagged[i] ? "#d00" : "#248");
  return svg + "</svg>\n";
}

std::string Section(const CharacteristicTrend& c) {
  // The name alone first in the heading (the page's tests read it); a
  // hole's quantity beside the type.
  const std::string quantity =
      c.quantity == "deviation" ? "" : absl::StrCat(", ", QuantityText(c.quantity));
  std::string html = absl::StrCat("<h2>", HtmlEscape(c.name), " <small>(", HtmlEscape(c.type),
                                  quantity, ", ", c.values_mm.size(), " parts)</small></h2>\n");
  if (!c.spc) return html + "<p>Fewer than 2 values: no SPC.</p>\n";
  const SpcResult& s = *c.spc;
  absl::StrAppend(
      &html, "<table><tr><th>tolerance mm</th><th>mean mm</th><th>&sigma; within mm</th>",
      "<th>&sigma; overall mm</th><th>Cp</th><th>Cpk</th><th>Pp</th><th>Ppk</th>",
      "<th>slope mm/part (95% CI)</th></tr><tr><td>[", Fmt(c.lower_mm), ", ", Fmt(c.upper_mm),
      "]</td><td>", Fmt(s.mean_mm), "</td><td>", Fmt(s.sigma_within_mm), "</td><td>",
      Fmt(s.sigma_overall_mm), "</td><td>", Fmt(s.cp, 2), "</td><td>", Fmt(s.cpk, 2), "</td><td>",
      Fmt(s.pp, 2), "</td><td>", Fmt(s.ppk, 2), "</td><td>");
  if (c.drift)
    absl::StrAppend(&html, Fmt(c.drift->slope_mm_per_part, 5, true), " [",
                    Fmt(c.drift->ci_lower, 5, true), ", ", Fmt(c.drift->ci_upper, 5, true), "]");
  absl::StrAppend(&html, "</td></tr></table>\n");
  std::vector<bool> flagged(c.values_mm.size(), false), mr_flagged(s.moving_ranges_mm.size());
  for (const RuleViolation& v : c.violations) flagged[v.index] = true;
  for (std::size_t i = 0; i < s.moving_ranges_mm.size(); ++i)
    mr_flagged[i] = s.moving_ranges_mm[i] > s.moving_range.upper;
  html += Chart("individuals (X), mm", c.values_mm,
                {s.individuals.center, s.individuals.lower, s.individuals.upper}, flagged, c.drift);
  html += Chart("moving range (MR), mm", s.moving_ranges_mm,
                {s.moving_range.center, s.moving_range.upper}, mr_flagged, std::nullopt);
  if (!c.violations.empty()) {
    html += "<p class=\"alarm\">Western Electric rules broken:";
    for (const RuleViolation& v : c.violations)
      absl::StrAppend(&html, " rule ", v.rule, " at ", HtmlEscape(c.part_ids[v.index]), ";");
    html += "</p>\n";
  }
  return html;
}

std::string Intro(const Trend& trend) {
  return absl::StrCat(
      "<p>", trend.part_ids.size(), " parts, from ", HtmlEscape(trend.part_ids.front()), " to ",
      HtmlEscape(trend.part_ids.back()),
      ". Values in mm; &sigma; within = MR&#772;/1.128; limits at &plusmn;3&sigma; within; "
      "the orange line is the drift line.</p>\n");
}

struct MapScale {
  double range_mm, band_mm;
};

// The largest |value| of the triangles (NaN skipped), at least 1 um; the
// band a quarter of it (trend_png.cpp's rule). Taken over the values as
// the page stores them (float), so the largest is inside the scale.
template <typename F>
MapScale ScaleOf(const TrendMap& map, F value) {
  double largest = 0;
  for (const TriangleTrend& t : map.triangles) {
    const double v = static_cast<float>(value(t));
    if (std::isfinite(v)) largest = std::max(largest, std::abs(v));
  }
  const double range = std::max(largest, 1e-3);
  return {range, range / 4};
}

// Per triangle of the mesh: mean, sigma (NaN without), part count and the
// palette index of each (index 0 where there is no value); `palette` gets
// the colours the indices refer to.
absl::StatusOr<nlohmann::json> TrendMapData(const TrendMap& map, std::size_t num_triangles,
                                            std::string& blob, nlohmann::json& palette) {
  std::vector<float> mean(num_triangles, NAN), sigma(num_triangles, NAN);
  std::vector<uint32_t> parts(num_triangles, 0);
  for (const TriangleTrend& t : map.triangles) {
    if (t.triangle_id >= num_triangles)
      return absl::InvalidArgumentError(absl::StrCat("trend map: triangle ", t.triangle_id,
                                                     " is not in the mesh of ", num_triangles,
                                                     " triangles"));
    mean[t.triangle_id] = static_cast<float>(t.mean_mm);
    sigma[t.triangle_id] = static_cast<float>(t.sigma_mm);
    parts[t.triangle_id] = t.parts;
  }
  const MapScale m = ScaleOf(map, [](const TriangleTrend& t) { return t.mean_mm; });
  const MapScale s = ScaleOf(map, [](const TriangleTrend& t) { return t.sigma_mm; });
  // The colours depend only on where a value lies in its scale
  // (DeviationColor), so one palette serves both.
  const DeviationPalette mean_palette = MakeDeviationPalette(m.band_mm, m.range_mm);
  const DeviationPalette sigma_palette = MakeDeviationPalette(s.band_mm, s.range_mm);
  std::vector<uint8_t> mean_index(num_triangles), sigma_index(num_triangles);
  for (std::size_t t = 0; t < num_triangles; ++t) {
    mean_index[t] = PaletteIndex(mean_palette, mean[t]);
    sigma_index[t] = PaletteIndex(sigma_palette, sigma[t]);
  }
  palette = PaletteJson(mean_palette);
  return nlohmann::json{{"parts", map.parts},
                        {"triangles_with_points", map.triangles.size()},
                        {"mean_range_mm", m.range_mm},
                        {"mean_band_mm", m.band_mm},
                        {"sigma_range_mm", s.range_mm},
                        {"sigma_band_mm", s.band_mm},
                        {"mean_mm", AppendToPayload(blob, mean)},
                        {"sigma_mm", AppendToPayload(blob, sigma)},
                        {"parts_per_triangle", AppendToPayload(blob, parts)},
                        {"mean_index", AppendToPayload(blob, mean_index)},
                        {"sigma_index", AppendToPayload(blob, sigma_index)}};
}

}  // namespace

absl::StatusOr<std::string> TrendViewerHtml(const Trend& trend, const std::string& title,
                                            const TriangleMesh& mesh) {
  std::string blob;
  nlohmann::json palette;
  ASSIGN_OR_RETURN(auto map, TrendMapData(trend.map, mesh.num_triangles(), blob, palette));
  std::vector<uint32_t> triangles;
  triangles.reserve(3 * mesh.num_triangles());
  for (const Triangle& t : mesh.triangles) triangles.insert(triangles.end(), t.begin(), t.end());
  nlohmann::json data = {{"kind", "trend_map"},
                         {"palette", std::move(palette)},
                         {"mesh", MeshJson(QuantisePositions(mesh.vertices), triangles, blob)},
                         {"trend", std::move(map)},
                         {"three", std::string(GetViewerAssets().three_version)}};
  std::string side = absl::StrCat("<aside id=\"side\">\n", Intro(trend));
  for (const CharacteristicTrend& c : trend.characteristics) side += Section(c);
  return absl::StrCat(
      ViewerHead(title), "<header class=\"banner trend\"><span class=\"verdict\">TREND</span>",
      "<span>", HtmlEscape(title), "</span><span class=\"reason\">", trend.part_ids.size(),
      " parts</span></header>\n<main class=\"trend\">\n",
      ViewerPane("<label><input type=\"radio\" name=\"trend-mode\" value=\"mean\" checked> mean"
                 "</label><label><input type=\"radio\" name=\"trend-mode\" value=\"sigma\"> "
                 "&sigma;</label>"),
      side, "</aside>\n</main>\n<footer>surfinspect process trend, three.js ",
      GetViewerAssets().three_version, "</footer>\n",
      ViewerScripts(data, absl::Base64Escape(blob)));
}

std::string TrendHtml(const Trend& trend, const std::string& title, const std::string& map_png) {
  std::string html = absl::StrCat(
      "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>", HtmlEscape(title),
      "</title><style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}"
      "td,th{border:1px solid #aaa;padding:2px 8px}.alarm{color:#d00}</style></head><body>\n"
      "<h1>",
      HtmlEscape(title), "</h1>\n", Intro(trend));
  for (const CharacteristicTrend& c : trend.characteristics) html += Section(c);
  if (!map_png.empty())
    absl::StrAppend(&html, "<h2>Process trend map</h2>\n<p>Mean deviation per CAD triangle over ",
                    trend.map.parts,
                    " parts.</p>\n<img alt=\"trend map\" src=\"data:image/png;base64,",
                    absl::Base64Escape(map_png), "\">\n");
  return html + "</body></html>\n";
}

}  // namespace surfinspect
