// The trend over parts (characteristics, SPC, rules, drift, map) and its
// writers: trend.json's documented keys, trend.html and trend.png. Also
// covers core/history/trend_html.cpp and core/history/trend_png.cpp.
#include "core/history/trend.h"

#include <gtest/gtest.h>

#include <random>

#include "core/history/trend_html.h"
#include "core/history/trend_png.h"
#include "tests/support/png_decode.h"
#include "tests/support/test_meshes.h"

namespace surfinspect {
namespace {

std::vector<PartRecord> Parts(int n, double slope) {
  std::mt19937_64 rng(4);
  std::normal_distribution<double> noise(0, 0.015);
  std::vector<PartRecord> parts;
  for (int k = 0; k < n; ++k) {
    PartRecord p;
    p.cell = "c";
    p.part_id = "p" + std::to_string(100 + k);
    CharacteristicRecord point, region;
    point.name = "ridge-centre", point.type = "point", point.value_mm = slope * k + noise(rng);
    point.lower_mm = -0.1, point.upper_mm = 0.1;
    region.name = "ridge", region.type = "region", region.value_mm = noise(rng);
    region.lower_mm = -0.15, region.upper_mm = 0.15;
    p.characteristics = {point, region};
    p.num_triangles = 8;
    for (uint32_t t = 0; t < 8; ++t)
      p.triangles.push_back(
          {t, 3, static_cast<float>((t == 5 ? slope * k : 0) + noise(rng) / 10), 0, 0});
    parts.push_back(p);
  }
  return parts;
}

TEST(Trend, SeriesSpcAndDrift) {
  auto trend = ComputeTrend(Parts(30, 0.005));
  ASSERT_TRUE(trend.ok()) << trend.status();
  ASSERT_EQ(trend->characteristics.size(), 2u);
  const CharacteristicTrend& c = trend->characteristics[0];
  EXPECT_EQ(c.name, "ridge-centre");
  EXPECT_EQ(c.values_mm.size(), 30u);
  ASSERT_TRUE(c.spc && c.drift);
  EXPECT_NEAR(c.drift->slope_mm_per_part, 0.005, 0.001);
  EXPECT_FALSE(c.violations.empty());  // a drift of 0.15 mm over the run breaks the rules
  EXPECT_EQ(trend->map.triangles[trend->map.largest].triangle_id, 5u);
}

TEST(Trend, JsonHasTheDocumentedKeys) {
  auto trend = ComputeTrend(Parts(30, 0.005), "ridge-centre");
  ASSERT_TRUE(trend.ok());
  const nlohmann::json j = TrendJson(*trend, {{"cell", "c"}});
  EXPECT_EQ(j["schema"], kTrendSchema);
  ASSERT_EQ(j["characteristics"].size(), 1u);
  const nlohmann::json& c = j["characteristics"][0];
  for (const char* key :
       {"name", "n", "mean_mm", "sigma_within_mm", "sigma_overall_mm", "cp", "cpk", "pp", "ppk",
        "slope_mm_per_part", "slope_ci_mm_per_part", "violations"})
    EXPECT_TRUE(c.contains(key)) << key;
  EXPECT_EQ(c["slope_ci_mm_per_part"].size(), 2u);
  ASSERT_FALSE(c["violations"].empty());
  EXPECT_TRUE(c["violations"][0].contains("rule"));
  EXPECT_EQ(c["violations"][0]["part_id"].get<std::string>().substr(0, 1), "p");
  EXPECT_EQ(j["trend_map"]["largest"]["triangle_id"], 5);
}

// Parts with a hole H1 (diameter deviation 0.01 k mm, true position 0.02 k
// mm) and a slot S1, the hole not measured on the third part.
std::vector<PartRecord> HoleParts(int n) {
  std::vector<PartRecord> parts;
  for (int k = 0; k < n; ++k) {
    PartRecord p;
    p.part_id = "p" + std::to_string(k);
    CharacteristicRecord h, s;
    h.name = "H1", h.type = "hole", h.lower_mm = -0.1, h.upper_mm = 0.1;
    h.position_tolerance_mm = 0.3;
    if (k != 2) {
      h.size_mm = 8 + 0.01 * k, h.size_deviation_mm = 0.01 * k;
      h.true_position_mm = 0.02 * k;
    }
    s.name = "S1", s.type = "slot", s.lower_mm = -0.1, s.upper_mm = 0.1;
    s.position_tolerance_mm = 0.2, s.length_lower_mm = -0.2, s.length_upper_mm = 0.3;
    s.size_deviation_mm = 0.001 * (k % 3), s.length_deviation_mm = 0.05 + 0.002 * (k % 2);
    s.true_position_mm = 0.05 + 0.001 * k;
    p.characteristics = {h, s};
    parts.push_back(p);
  }
  return parts;
}

TEST(Trend, HolesChartTheirSizesAndTruePosition) {
  auto trend = ComputeTrend(HoleParts(6));
  ASSERT_TRUE(trend.ok()) << trend.status();
  std::vector<std::string> labels;
  for (const CharacteristicTrend& c : trend->characteristics) labels.push_back(TrendLabel(c));
  EXPECT_EQ(labels, (std::vector<std::string>{"H1 diameter", "H1 true position", "S1 width",
                                              "S1 length", "S1 true position"}));
  const CharacteristicTrend& d = trend->characteristics[0];
  EXPECT_EQ(d.quantity, "diameter");
  EXPECT_EQ(d.values_mm, (std::vector<double>{0, 0.01, 0.03, 0.04, 0.05}));  // not p2
  EXPECT_EQ(d.part_ids[2], "p3");
  EXPECT_EQ(d.upper_mm, 0.1);
  const CharacteristicTrend& tp = trend->characteristics[1];
  ASSERT_TRUE(tp.spc);
  EXPECT_EQ(tp.lower_mm, -INFINITY);  // one-sided: Cp undefined, Cpk of the zone
  EXPECT_TRUE(std::isnan(tp.spc->cp));
  EXPECT_NEAR(tp.spc->cpk, (0.3 - tp.spc->mean_mm) / (3 * tp.spc->sigma_within_mm), 1e-12);
  EXPECT_EQ(trend->characteristics[3].lower_mm, -0.2);  // the length's own band
  // A name takes all of its quantities; trend.json says which each is.
  auto s1 = ComputeTrend(HoleParts(6), "S1");
  ASSERT_TRUE(s1.ok());
  ASSERT_EQ(s1->characteristics.size(), 3u);
  const nlohmann::json j = TrendJson(*s1, {});
  EXPECT_EQ(j["characteristics"][1]["quantity"], "length");
  EXPECT_EQ(j["characteristics"][2]["quantity"], "true_position");
  EXPECT_TRUE(j["characteristics"][2]["tolerance_mm"]["lower"].is_null());
  const std::string html = TrendHtml(*s1, "t", "");
  EXPECT_NE(html.find("<h2>S1 <small>(slot, true position, 6 parts)</small></h2>"),
            std::string::npos);
}

TEST(Trend, RefusesEmptySelectionAndUnknownCharacteristic) {
  EXPECT_EQ(ComputeTrend({}).status().code(), absl::StatusCode::kNotFound);
  const auto st = ComputeTrend(Parts(3, 0), "ridge-left").status();
  EXPECT_NE(st.message().find("unknown characteristic 'ridge-left'"), std::string::npos) << st;
  EXPECT_NE(st.message().find("ridge-centre, ridge"), std::string::npos) << st;
}

TEST(Trend, HtmlAndPng) {
  auto trend = ComputeTrend(Parts(30, 0.005));
  ASSERT_TRUE(trend.ok());
  const TriangleMesh mesh =  // 2 x 2 cells, 8 triangles, all facing +z
      testing::HeightField(0, 100, 0, 50, 3, 3, [](double, double) { return 0.0; });
  auto img = RenderTrendMap(trend->map, mesh);
  ASSERT_TRUE(img.ok()) << img.status();
  auto png = EncodePng(*img);
  ASSERT_TRUE(png.ok());
  const RgbImage back = testing::DecodePng(*png);
  EXPECT_EQ(back.width, img->width);
  // Triangle 5 carries the drift: its colour is warm (red channel high, blue low).
  bool warm = false;
  for (const Rgb& p : back.pixels) warm = warm || (p.r > 200 && p.b < 60 && p.g < 200);
  EXPECT_TRUE(warm);
  const std::string html = TrendHtml(*trend, "t <1>", *png);
  EXPECT_NE(html.find("<svg"), std::string::npos);
  EXPECT_NE(html.find("t &lt;1&gt;"), std::string::npos);
  EXPECT_NE(html.find("data:image/png;base64,"), std::string::npos);
  EXPECT_NE(html.find("Western Electric rules broken"), std::string::npos);
  TrendMap bad = trend->map;
  bad.triangles.push_back({99, 1, 0, 0});
  EXPECT_FALSE(RenderTrendMap(bad, mesh).ok());
}

// The 3D page: the viewer's data names the page a trend map, the title is
// escaped, and a triangle the mesh lacks is refused by name.
// tests/report/trend_browser_test.py checks it in a browser.
TEST(TrendViewerHtml, CarriesTheMapForTheViewer) {
  auto trend = ComputeTrend(Parts(30, 0.005));
  ASSERT_TRUE(trend.ok());
  const TriangleMesh mesh =
      testing::HeightField(0, 100, 0, 50, 3, 3, [](double, double) { return 0.0; });
  auto html = TrendViewerHtml(*trend, "t <1>", mesh);
  ASSERT_TRUE(html.ok()) << html.status();
  EXPECT_NE(html->find("\"kind\":\"trend_map\""), std::string::npos);
  EXPECT_NE(html->find("<title>t &lt;1&gt;</title>"), std::string::npos);
  EXPECT_EQ(html->find("t <1>"), std::string::npos);
  EXPECT_NE(html->find("name=\"trend-mode\" value=\"sigma\""), std::string::npos);
  EXPECT_NE(html->find("Western Electric rules broken"), std::string::npos);
  Trend bad = *trend;
  bad.map.triangles.push_back({99, 1, 0, 0});
  auto refused = TrendViewerHtml(bad, "t", mesh);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("triangle 99 is not in the mesh of 8"),
            std::string::npos);
}

}  // namespace
}  // namespace surfinspect
