// core/report/html_section_plot.cpp: one SVG plot per section in the HTML
// report, its whisker lines and nominal polylines counted and the drawn
// coordinates read back against the plane's basis worked out by hand.
#include "core/report/html_section_plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <regex>

#include "core/report/html_report.h"

namespace surfinspect {
namespace {

using nlohmann::json;

std::size_t Count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// A ridge across the plane x = 0 (y from -20 to 20, z = 60 - y^2 / 100) with
// five whiskers, and a second section in z = 10 with two polylines.
json ReportJson() {
  json ridge = {{"name", "ridge <x0>"},
                {"point_mm", {0, 0, 0}},
                {"normal", {1, 0, 0}},
                {"tolerance_mm", {{"lower", -0.15}, {"upper", 0.15}}}};
  json xyz = json::array();
  for (int i = 0; i <= 8; ++i) {
    const double y = -20 + 5 * i;
    xyz.insert(xyz.end(), {0.0, y, 60 - y * y / 100});
  }
  ridge["polylines"] = {{{"xyz_mm", xyz}}};
  ridge["whiskers"] = {{"at_mm", {0, -10, 59, 0, -5, 59.75, 0, 0, 60, 0, 5, 59.75, 0, 10, 59}},
                       {"direction", {0, 0, 1, 0, 0.6, 0.8, 0, 0, 1, 0, -0.6, 0.8, 0, -0.8, 0.6}},
                       {"deviation_mm", {-0.2, -0.05, 0, 0.1, 0.3}}};
  json flat = {{"name", "flat"},
               {"point_mm", {0, 0, 10}},
               {"normal", {0, 0, 1}},
               {"tolerance_mm", {{"lower", -0.1}, {"upper", 0.1}}},
               {"polylines",
                {{{"xyz_mm", {0, 0, 10, 10, 0, 10, 10, 10, 10}}},
                 {{"xyz_mm", {20, 0, 10, 30, 0, 10, 30, 5, 10, 20, 5, 10}}}}},
               {"whiskers",
                {{"at_mm", {5, 0, 10, 10, 5, 10}},
                 {"direction", {0, -1, 0, 1, 0, 0}},
                 {"deviation_mm", {0.05, -0.4}}}}};
  return {{"schema", "surfinspect.report/2"},
          {"verdict", "fail"},
          {"color_range_mm", 0.5},
          {"tolerance", {{"band_mm", 0.15}, {"reason", "r"}}},
          {"characteristics",
           {{{"name", "ridge <x0>"},
             {"type", "section"},
             {"verdict", "fail"},
             {"points", 321},
             {"min_mm", -0.2},
             {"max_mm", 0.3},
             {"mean_mm", 0.031}}}},
          {"sections", {ridge, flat}}};
}

InspectionReport Typed(const json& j) {
  absl::StatusOr<InspectionReport> r = DecodeReport(j);
  EXPECT_TRUE(r.ok()) << r.status();
  return r.ok() ? *std::move(r) : InspectionReport{};
}

// The figures of the page, in order.
std::vector<std::string> Figures(const std::string& html) {
  std::vector<std::string> out;
  for (auto at = html.find("<figure class=\"section\""); at != std::string::npos;
       at = html.find("<figure class=\"section\"", at + 1))
    out.push_back(html.substr(at, html.find("</figure>", at) - at));
  return out;
}

struct Segment {
  double x1, y1, x2, y2;
  std::string stroke;
};

std::vector<Segment> Whiskers(const std::string& figure) {
  static const std::regex line(
      R"re(<line class="whisker" x1="([-0-9.]+)" y1="([-0-9.]+)" x2="([-0-9.]+)" y2="([-0-9.]+)" stroke="(#[0-9a-f]{6})")re");
  std::vector<Segment> out;
  for (auto it = std::sregex_iterator(figure.begin(), figure.end(), line);
       it != std::sregex_iterator(); ++it)
    out.push_back({std::stod((*it)[1]), std::stod((*it)[2]), std::stod((*it)[3]),
                   std::stod((*it)[4]), (*it)[5]});
  return out;
}

// The vertex counts of the figure's nominal polylines.
std::vector<std::size_t> PolylineVertices(const std::string& figure) {
  static const std::regex polyline(R"re(<polyline class="nominal"[^>]* points="([^"]*)")re");
  std::vector<std::size_t> out;
  for (auto it = std::sregex_iterator(figure.begin(), figure.end(), polyline);
       it != std::sregex_iterator(); ++it)
    out.push_back(Count((*it)[1].str(), ",") /* one comma per x,y pair */);
  return out;
}

TEST(HtmlSectionPlot, OnePlotPerSectionWithItsWhiskersAndPolylines) {
  const InspectionReport report = Typed(ReportJson());
  const DeviationPalette palette = MakeDeviationPalette(0.15, 0.5);
  const std::string html = SectionPlotsHtml(report, palette);
  EXPECT_EQ(Count(html, "<svg class=\"section-plot\""), 2u);
  const std::vector<std::string> figures = Figures(html);
  ASSERT_EQ(figures.size(), 2u);
  EXPECT_NE(figures[0].find("data-section=\"ridge &lt;x0&gt;\""), std::string::npos);
  EXPECT_EQ(Whiskers(figures[0]).size(), 5u);
  EXPECT_EQ(Whiskers(figures[1]).size(), 2u);
  EXPECT_EQ(PolylineVertices(figures[0]), (std::vector<std::size_t>{9}));
  EXPECT_EQ(PolylineVertices(figures[1]), (std::vector<std::size_t>{3, 4}));
  EXPECT_EQ(Count(figures[0], "<path class=\"band\""), 1u);
  // The title from the section's characteristic, escaped; the caption's k.
  EXPECT_NE(figures[0].find("ridge &lt;x0&gt;: fail, 321 points, min -0.200, max +0.300, mean "
                            "+0.031 mm"),
            std::string::npos);
  // Extent 40 mm (y from -20 to 20), band 0.3 mm: 0.05 * 40 / 0.3 = 6.7 -> 5.
  EXPECT_NE(figures[0].find("data-exaggeration=\"5\""), std::string::npos);
  EXPECT_NE(figures[0].find("whiskers x 5, band -0.150..+0.150 mm; right +y, up +z"),
            std::string::npos);
  // Extent 30 mm, band 0.2 mm: 7.5 -> 5; seen from +z: right +x, up +y.
  EXPECT_NE(figures[1].find("whiskers x 5, band -0.100..+0.100 mm; right +x, up +y"),
            std::string::npos);
}

TEST(HtmlSectionPlot, AWhiskerEndsAtItsFootPlusKTimesItsDeviationAlongItsDirection) {
  const json j = ReportJson();
  const InspectionReport report = Typed(j);
  const DeviationPalette palette = MakeDeviationPalette(0.15, 0.5);
  const std::vector<std::string> figures = Figures(SectionPlotsHtml(report, palette));
  ASSERT_EQ(figures.size(), 2u);
  // The plane x = 0 seen from +x: right is +y, up is +z, from the origin.
  const json& w = j["sections"][0]["whiskers"];
  const std::vector<Segment> drawn = Whiskers(figures[0]);
  ASSERT_EQ(drawn.size(), 5u);
  for (std::size_t i = 0; i < 5; ++i) {
    const double y = w["at_mm"][3 * i + 1], z = w["at_mm"][3 * i + 2];
    const double dy = w["direction"][3 * i + 1], dz = w["direction"][3 * i + 2];
    const double dev = w["deviation_mm"][i];
    EXPECT_NEAR(drawn[i].x1, y, 1e-4) << i;
    EXPECT_NEAR(drawn[i].y1, z, 1e-4) << i;
    EXPECT_NEAR(drawn[i].x2, y + 5 * dev * dy, 1e-4) << i;
    EXPECT_NEAR(drawn[i].y2, z + 5 * dev * dz, 1e-4) << i;
    const Rgb c = palette.colors[PaletteIndex(palette, static_cast<float>(dev))];
    char hex[8];
    std::snprintf(hex, sizeof hex, "#%02x%02x%02x", c.r, c.g, c.b);
    EXPECT_EQ(drawn[i].stroke, hex) << i;
  }
  EXPECT_NE(drawn[0].stroke, drawn[2].stroke) << "-0.2 is outside the band, 0 inside";
  // The plane z = 10 seen from +z: right is +x, up is +y, from (0, 0, 10).
  const std::vector<Segment> flat = Whiskers(figures[1]);
  ASSERT_EQ(flat.size(), 2u);
  EXPECT_NEAR(flat[1].x1, 10, 1e-4);
  EXPECT_NEAR(flat[1].x2, 10 + 5 * -0.4, 1e-4);
  EXPECT_NEAR(flat[1].y2, 5, 1e-4);
}

TEST(HtmlSectionPlot, TheReportPageCarriesThePlotsOnlyWithSections) {
  PointCloud cloud;
  cloud.points = {{0, 0, 0}, {1, 0, 0}};
  cloud.width = 2;
  cloud.height = 1;
  const std::vector<float> deviation = {0.0f, 0.1f};
  const InspectionReport with = Typed(ReportJson());
  json none_json = ReportJson();
  none_json.erase("sections");
  const InspectionReport without = Typed(none_json);
  for (const InspectionReport* report : {&with, &without}) {
    HtmlReportInput in;
    in.report = report;
    in.points_in_part = &cloud;
    in.deviation_mm = &deviation;
    const absl::StatusOr<HtmlReportPage> page = BuildHtmlReport(in);
    ASSERT_TRUE(page.ok()) << page.status();
    const bool sections = report == &with;
    EXPECT_EQ(Count(page->html, "<h2>Sections</h2>"), sections ? 1u : 0u);
    EXPECT_EQ(Count(page->html, "<svg class=\"section-plot\""), sections ? 2u : 0u);
  }
  EXPECT_EQ(SectionPlotsHtml(without, MakeDeviationPalette(0.15, 0.5)), "");
}

}  // namespace
}  // namespace surfinspect
