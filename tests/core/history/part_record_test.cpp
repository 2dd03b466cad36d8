// A part's record from report.json: the charted value per characteristic
// type, tolerances, defects; bad reports are named.
#include "core/history/part_record.h"

#include <gtest/gtest.h>

namespace surfinspect {
namespace {

TEST(PartRecord, FromReport) {
  const std::string defects =
      R"([{"area_mm2":12.5,"centroid_mm":[1.5,-2.0,60.0],"extent_mm":4.0,"id":1,"kind":"dent","measured_extreme_mm":-0.27,"noise_mm":0.015,"peak_mm":-0.25,"peak_source":"fit","points":180,"region":"ridge"}])";
  const std::string report = R"({"verdict": "fail", "defects": )" + defects + R"(,
    "characteristics": [
      {"name": "surface", "type": "surface", "verdict": "pass", "mean_mm": 0.01, "min_mm": -0.2,
       "max_mm": 0.3, "stddev_mm": 0.02, "points": 1000,
       "tolerance_mm": {"lower": -0.3, "upper": 0.3}},
      {"name": "ridge-centre", "type": "point", "verdict": "fail", "mean_mm": 0.05,
       "value_mm": 0.12, "points": 30, "tolerance_mm": {"lower": -0.1, "upper": 0.1}},
      {"name": "empty", "type": "point", "verdict": "fail", "mean_mm": null, "value_mm": null,
       "points": 0, "tolerance_mm": {"lower": -0.1, "upper": 0.1}}]})";
  PartRecord r;
  ASSERT_TRUE(FillFromReportJson(report, "r.json", &r).ok());
  EXPECT_EQ(r.verdict, "fail");
  ASSERT_EQ(r.characteristics.size(), 3u);
  EXPECT_EQ(r.characteristics[0].value_mm, 0.01);  // surface: mean_mm
  EXPECT_EQ(r.characteristics[1].value_mm, 0.12);  // point: value_mm
  EXPECT_EQ(r.characteristics[1].lower_mm, -0.1);
  EXPECT_EQ(r.characteristics[0].points, 1000);
  EXPECT_TRUE(std::isnan(r.characteristics[2].value_mm));
  EXPECT_EQ(r.defects_json, defects);
}

TEST(PartRecord, BadReportsAreNamed) {
  PartRecord r;
  EXPECT_NE(FillFromReportJson("{", "a/report.json", &r).message().find("a/report.json"),
            std::string::npos);
  EXPECT_NE(FillFromReportJson("{}", "b.json", &r).message().find("no verdict"), std::string::npos);
  EXPECT_FALSE(
      FillFromReportJson(R"({"verdict":"pass","characteristics":[{"x":1}]})", "c", &r).ok());
}

}  // namespace
}  // namespace surfinspect
