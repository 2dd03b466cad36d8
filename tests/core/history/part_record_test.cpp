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

// A hole keeps its measured diameter and true position, a slot its length
// too; a hole not measured keeps its bands and NaN (NULL) for the rest.
TEST(PartRecord, HolesKeepTheirSizesAndTruePosition) {
  const std::string report = R"({"verdict": "fail", "characteristics": [
      {"name": "H1", "type": "hole", "verdict": "fail", "points": 180,
       "tolerance_mm": {"lower": -0.1, "upper": 0.1}, "true_position_mm": 0.31,
       "position_tolerance_mm": 0.3, "measured_diameter_mm": 8.012,
       "diameter_deviation_mm": 0.012},
      {"name": "S1", "type": "slot", "verdict": "pass", "points": 300,
       "tolerance_mm": {"lower": -0.1, "upper": 0.1}, "true_position_mm": 0.12,
       "position_tolerance_mm": 0.2, "measured_width_mm": 6.05, "width_deviation_mm": 0.05,
       "measured_length_mm": 14.1, "length_deviation_mm": 0.1,
       "length_tolerance_mm": {"lower": -0.2, "upper": 0.3}},
      {"name": "H9", "type": "hole", "verdict": "not_measured", "points": 0,
       "tolerance_mm": {"lower": -0.1, "upper": 0.1}, "position_tolerance_mm": 0.2,
       "true_position_mm": null, "measured_diameter_mm": null}]})";
  PartRecord r;
  ASSERT_TRUE(FillFromReportJson(report, "r.json", &r).ok());
  ASSERT_EQ(r.characteristics.size(), 3u);
  const CharacteristicRecord &h = r.characteristics[0], &s = r.characteristics[1],
                             &u = r.characteristics[2];
  EXPECT_EQ(h.size_mm, 8.012);
  EXPECT_EQ(h.size_deviation_mm, 0.012);
  EXPECT_EQ(h.true_position_mm, 0.31);
  EXPECT_EQ(h.position_tolerance_mm, 0.3);
  EXPECT_EQ(h.upper_mm, 0.1);
  EXPECT_TRUE(std::isnan(h.length_mm));
  EXPECT_TRUE(std::isnan(h.value_mm)) << "a hole's quantities are its own fields";
  EXPECT_EQ(s.size_mm, 6.05);
  EXPECT_EQ(s.length_mm, 14.1);
  EXPECT_EQ(s.length_deviation_mm, 0.1);
  EXPECT_EQ(s.length_lower_mm, -0.2);
  EXPECT_EQ(s.length_upper_mm, 0.3);
  EXPECT_EQ(u.verdict, "not_measured");
  EXPECT_TRUE(std::isnan(u.size_mm) && std::isnan(u.true_position_mm));
  EXPECT_EQ(u.position_tolerance_mm, 0.2);
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
