// Tests of the HTML report: core/report/html_report.cpp (the page),
// core/report/html_escape.cpp, core/report/html_sections.cpp and
// core/report/html_histogram.cpp (its parts).
#include "core/report/html_report.h"

#include <gtest/gtest.h>

#include <regex>

#include "core/pipeline/inspection_report.h"
#include "core/report/html_escape.h"
#include "core/report/html_histogram.h"
#include "tests/support/temp_dir.h"

namespace surfinspect {
namespace {

using nlohmann::json;

const std::string kEvil = "<script>alert(\"x\")</script> it's & \"quoted\"";

std::size_t Count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

json Report() {
  return json::parse(R"({
    "schema": "surfinspect.report/2", "verdict": "fail", "color_range_mm": 1.0,
    "tolerance": {"band_mm": 0.3, "reason": "fail: too much outside", "within": 9, "above": 1,
                  "below": 0, "fraction_within": 0.9},
    "points": {"count": 12, "valid": 11, "matched": 10},
    "statistics": {"min_mm": -0.25, "max_mm": 0.75, "mean_mm": 0.1234567890123,
                   "stddev_mm": 0.2, "rms_mm": 0.21, "p1_mm": -0.2, "p5_mm": -0.1,
                   "p50_mm": 0.05, "p95_mm": 0.5, "p99_mm": 0.7},
    "histogram": {"min_mm": -1, "max_mm": 1, "counts": [0, 1, 1000000, 2, 0],
                  "below_range": 0, "above_range": 3},
    "settings": {"tolerance_mm": 0.3, "histogram_bins": 5},
    "characteristics": [
      {"name": "surface", "type": "surface", "verdict": "pass", "points": 10,
       "tolerance_mm": {"lower": -0.3, "upper": 0.3}},
      {"name": "REGION", "type": "region", "verdict": "fail", "points": 4,
       "tolerance_mm": {"lower": -0.1, "upper": 0.1}, "reason": "REGION"}],
    "defects": [{"id": 1, "kind": "dent", "centroid_mm": [1, 2, 3], "extent_mm": 4,
                 "peak_mm": -0.4, "points": 7, "area_mm2": 5, "region": "REGION"}]
  })");
}

json EvilReport() {
  json r = Report();
  r["characteristics"][1]["name"] = kEvil;
  r["characteristics"][1]["reason"] = kEvil;
  r["defects"][0]["region"] = kEvil;
  r["inputs"] = {{"cloud", kEvil + ".ply"}};
  return r;
}

struct Points {
  PointCloud cloud;
  std::vector<float> deviation;
};

Points SomePoints(std::size_t n) {
  Points p;
  for (std::size_t i = 0; i < n; ++i) {
    p.cloud.points.emplace_back(static_cast<float>(i % 100), static_cast<float>(i / 100), 0.0f);
    p.deviation.push_back(static_cast<float>(i % 17) / 10 - 0.8f);
  }
  p.cloud.width = static_cast<uint32_t>(n);
  p.cloud.height = 1;
  return p;
}

std::string ScriptText(const std::string& html, const std::string& id) {
  const std::string open = "id=\"" + id + "\">";
  const auto begin = html.find(open);
  EXPECT_NE(begin, std::string::npos) << id;
  const auto end = html.find("</script>", begin);
  return html.substr(begin + open.size(), end - begin - open.size());
}

// The typed report of a report.json object (the decoding must succeed).
InspectionReport Typed(const json& j) {
  absl::StatusOr<InspectionReport> r = DecodeReport(j);
  EXPECT_TRUE(r.ok()) << r.status();
  return r.ok() ? *std::move(r) : InspectionReport{};
}

absl::StatusOr<HtmlReportPage> Page(const json& report_json, const Points& p,
                                    const std::string& part_id = "part-1",
                                    std::size_t max_points = 1'000'000) {
  const InspectionReport report = Typed(report_json);
  HtmlReportInput in;
  in.report = &report;
  in.points_in_part = &p.cloud;
  in.deviation_mm = &p.deviation;
  in.context.part_id = part_id;
  in.context.cell = "cell-A";
  in.context.viewpoints = {{"v1", true, {{"rms_mm", 0.014}, {"converged", true}}},
                           {"v2", false, nullptr}};
  in.payload.max_points = max_points;
  return BuildHtmlReport(in);
}

TEST(HtmlEscape, EscapesMarkupAndQuotes) {
  EXPECT_EQ(HtmlEscape("<a href=\"x\">'&'</a>"),
            "&lt;a href=&quot;x&quot;&gt;&#39;&amp;&#39;&lt;/a&gt;");
  EXPECT_EQ(HtmlEscape("plain part-001"), "plain part-001");
}

TEST(HtmlEscape, JsonForScriptCannotCloseTheElementAndParsesBack) {
  const json value = {{"name", kEvil}, {"sep", "a\u2028b\u2029c"}, {"comment", "<!-- -->"}};
  const std::string text = JsonForScript(value);
  EXPECT_EQ(text.find('<'), std::string::npos);
  EXPECT_EQ(text.find('>'), std::string::npos);
  EXPECT_EQ(text.find('&'), std::string::npos);
  EXPECT_EQ(text.find("\xE2\x80\xA8"), std::string::npos);
  EXPECT_EQ(json::parse(text), value);
}

TEST(HtmlReport, NothingFromOutsideBecomesMarkup) {
  const Points p = SomePoints(500);
  auto page = Page(EvilReport(), p, "<b>\"part\"</b>");
  ASSERT_TRUE(page.ok()) << page.status();
  const std::string& html = page->html;
  // Only the page's own four script elements: import map, data, payload, viewer.
  EXPECT_EQ(Count(html, "<script"), 4u);
  EXPECT_EQ(Count(html, "</script"), 4u);
  EXPECT_EQ(Count(html, "<b>"), 0u);
  EXPECT_GE(Count(html, "&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt; it&#39;s &amp;"), 4u);
  EXPECT_NE(html.find("&lt;b&gt;&quot;part&quot;&lt;/b&gt;"), std::string::npos);
  const json data = json::parse(ScriptText(html, "si-data"));
  EXPECT_EQ(data["defects"][0]["region"], kEvil);
  EXPECT_EQ(data["part_id"], "<b>\"part\"</b>");
}

TEST(HtmlReport, StatisticsAreTheReportsWhateverTheThinning) {
  const Points p = SomePoints(20000);
  auto full = Page(Report(), p);
  auto thin = Page(Report(), p, "part-1", 1000);
  ASSERT_TRUE(full.ok() && thin.ok());
  EXPECT_EQ(full->shown_points, 20000u);
  EXPECT_LE(thin->shown_points, 1000u);
  const std::regex cell(R"re(data-key="([a-z0-9_]+)" data-value="([^"]*)")re");
  auto values = [&](const std::string& html) {
    std::map<std::string, std::string> out;
    for (auto it = std::sregex_iterator(html.begin(), html.end(), cell);
         it != std::sregex_iterator(); ++it)
      out[(*it)[1]] = (*it)[2];
    return out;
  };
  const auto a = values(full->html), b = values(thin->html);
  EXPECT_EQ(a, b);
  const json report = Report();
  ASSERT_EQ(a.count("mean_mm"), 1u);
  EXPECT_EQ(json::parse(a.at("mean_mm")).get<double>(),
            report["statistics"]["mean_mm"].get<double>());
  EXPECT_EQ(a.at("matched"), "10");
  EXPECT_EQ(a.at("p99_mm"), "0.7");
}

TEST(HtmlReport, PanelsFailedFirstDefectsCalibrationHistogram) {
  const Points p = SomePoints(100);
  auto page = Page(Report(), p);
  ASSERT_TRUE(page.ok());
  const std::string& html = page->html;
  EXPECT_LT(html.find("<td>REGION</td>"), html.find("<td>surface</td>"));  // failed first
  EXPECT_NE(html.find("data-defect=\"1\""), std::string::npos);
  EXPECT_NE(html.find("class=\"banner fail\""), std::string::npos);
  EXPECT_NE(html.find("<td>v2</td><td class=\"fail\">not calibrated</td>"), std::string::npos);
  EXPECT_NE(html.find("<svg id=\"histogram\""), std::string::npos);
  EXPECT_NE(html.find("type=\"importmap\""), std::string::npos);
  EXPECT_EQ(html.find("https://"), std::string::npos);  // no network
}

// A hole's row shows its size, true position and arc seen, one per line,
// the same text as the PDF's table (core/report/report_content.h).
TEST(HtmlReport, AHoleRowShowsSizeTruePositionAndArc) {
  json r = Report();
  r["characteristics"].push_back(json::parse(R"({
      "name": "H1", "type": "hole", "verdict": "fail", "reason": "fail: true position",
      "tolerance_mm": {"lower": -0.1, "upper": 0.1}, "points": 180,
      "true_position_mm": 0.31, "position_tolerance_mm": 0.3, "measured_diameter_mm": 8.012,
      "diameter_deviation_mm": 0.012, "arc_coverage_deg": 351})"));
  const Points p = SomePoints(100);
  auto page = Page(r, p);
  ASSERT_TRUE(page.ok()) << page.status();
  const std::string& html = page->html;
  EXPECT_NE(html.find("<td>H1</td><td>hole</td><td class=\"fail\">fail</td>"
                      "<td>\u00d8 -0.100 / +0.100<br>TP 0.300</td>"
                      "<td>\u00d8 8.012 (+0.012)<br>TP 0.310 / 0.300</td><td>-</td><td>-</td>"
                      "<td>arc 351\u00b0</td><td>180</td>"),
            std::string::npos)
      << html.substr(html.find("<table id=\"characteristics\""), 1500);
}

// An aligned part's side pane shows the alignment's lines and each RPS
// reference's deviations, before and after, as the PDF prints them; a
// calibrated report has no alignment section.
TEST(HtmlReport, AnAlignedPartShowsItsAlignment) {
  const Points p = SomePoints(100);
  auto plain = Page(Report(), p);
  ASSERT_TRUE(plain.ok());
  EXPECT_EQ(plain->html.find("<h2>Alignment</h2>"), std::string::npos);
  json r = Report();
  r["alignment"] = json::parse(R"({
      "mode": "rps", "aligned": true, "failure": "", "note": "",
      "matrix": [1,0,0,0.1, 0,1,0,0, 0,0,1,0, 0,0,0,1],
      "correction_mm": 0.1, "correction_deg": 0.0, "max_correction_mm": 2,
      "max_correction_deg": 1, "within_max_correction": true, "rms_before_mm": 0.07,
      "rms_after_mm": 0.002, "dofs": 6,
      "references": [
        {"name": "A1", "kind": "hole", "measured": true, "nominal_mm": [0, 0, 0],
         "measured_mm": [0.1, 0, 0], "points": 120,
         "locked": [{"direction": [1, 0, 0], "before_mm": 0.1, "after_mm": 0.001},
                    {"direction": [0, 1, 0], "before_mm": 0.0, "after_mm": -0.002}]},
        {"name": "B1", "kind": "surface", "measured": false, "nominal_mm": [0, 0, 60],
         "measured_mm": null, "points": 3, "locked": [{"direction": [0, 0, 1]}]}]})");
  auto page = Page(r, p);
  ASSERT_TRUE(page.ok()) << page.status();
  const std::string& html = page->html;
  EXPECT_NE(html.find("<h2>Alignment</h2>\n<p id=\"alignment-lines\">rps: corrected 0.100 mm / "
                      "0.0000 deg (allowed 2 mm / 1 deg), rms 0.0700 -&gt; 0.0020 mm<br></p>"),
            std::string::npos)
      << html.substr(html.find("<h2>Alignment</h2>"), 300);
  EXPECT_NE(html.find("<td>A1</td><td>hole</td><td class=\"pass\">yes</td>"
                      "<td>(1.000, 0.000, 0.000)<br>(0.000, 1.000, 0.000)</td>"
                      "<td>+0.100<br>+0.000</td><td>+0.001<br>-0.002</td><td>120</td>"),
            std::string::npos);
  EXPECT_NE(html.find("<td>B1</td><td>surface</td><td class=\"fail\">no</td>"), std::string::npos);
}

TEST(HtmlHistogram, LogAxisKeepsSmallBinsVisible) {
  const std::string svg = HistogramSvg(Typed(Report()).histogram, MakeDeviationPalette(0.3, 1.0));
  // The bin with 1 count is log10(2) / log10(1e6 + 1) ~ 5% of the tallest, not 1e-6.
  const std::regex bar(R"re(<rect x="[0-9.]+" y="[0-9.]+" width="[0-9.]+" height="([0-9.]+)")re");
  std::vector<double> heights;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), bar); it != std::sregex_iterator();
       ++it)
    heights.push_back(std::stod((*it)[1]));
  ASSERT_EQ(heights.size(), 5u);
  EXPECT_NEAR(heights[1] / heights[2], std::log10(2.0) / std::log10(1e6 + 1), 1e-3);
  EXPECT_EQ(heights[0], 0);
  EXPECT_NE(svg.find("class=\"band\""), std::string::npos);
}

TEST(HtmlReport, RefusesIncompleteInput) {
  const Points p = SomePoints(10);
  json no_band = Report();
  no_band["tolerance"].erase("band_mm");
  EXPECT_EQ(Page(no_band, p).status().code(), absl::StatusCode::kInvalidArgument);
  HtmlReportInput in;
  EXPECT_EQ(BuildHtmlReport(in).status().code(), absl::StatusCode::kInvalidArgument);
  // Fields of unexpected types are refused when the report is decoded, never
  // a crash; a report without a histogram is drawn without one.
  json odd = Report();
  odd["verdict"] = 3;
  odd["histogram"] = "none";
  odd["defects"] = {1, "two", nullptr};
  odd["characteristics"] = 5;
  odd["statistics"] = nullptr;
  EXPECT_EQ(DecodeReport(odd).status().code(), absl::StatusCode::kDataLoss);
  json no_histogram = Report();
  no_histogram.erase("histogram");
  auto page = Page(no_histogram, p);
  ASSERT_TRUE(page.ok()) << page.status();
  EXPECT_NE(page->html.find("no histogram"), std::string::npos);
}

TEST(HtmlReport, WritesTheFile) {
  testing::TempDir dir;
  const Points p = SomePoints(10);
  const InspectionReport report = Typed(Report());
  HtmlReportInput in;
  in.report = &report;
  in.points_in_part = &p.cloud;
  in.deviation_mm = &p.deviation;
  ASSERT_TRUE(WriteHtmlReport(dir.File("report.html"), in).ok());
  EXPECT_EQ(testing::ReadBytes(dir.File("report.html")).rfind("<!doctype html>", 0), 0u);
}

}  // namespace
}  // namespace surfinspect
