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
