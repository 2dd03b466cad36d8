#include "core/errormap/plan_report.h"

#include <gtest/gtest.h>

#include <set>

namespace surfinspect {
namespace {

std::set<std::string> Keys(const nlohmann::json& j) {
  std::set<std::string> keys;
  for (const auto& [k, v] : j.items()) keys.insert(k);
  return keys;
}

TEST(PlanReport, CharacteristicsCarryTheSchemaFields) {
  CharacteristicsResult r;
  CharacteristicResult surface;
  surface.name = "surface";
  surface.pass = true;
  surface.reason = "pass: ...";
  surface.tolerance = {-0.1, 0.2};
  surface.points = 10;
  surface.min_mm = -0.05;
  surface.max_mm = 0.15;
  surface.mean_mm = 0.01;
  surface.stddev_mm = 0.02;
  surface.rms_mm = 0.03;
  surface.fraction_within = 0.9;
  surface.allowed_fraction_outside = 0.1;
  CharacteristicResult point;
  point.name = "P1";
  point.type = CharacteristicType::kPoint;
  point.reason = "fail: unmeasured";
  r.characteristics = {surface, point};

  const nlohmann::json j = CharacteristicsJson(r);
  ASSERT_TRUE(j.is_array());
  ASSERT_EQ(j.size(), 2u);
  const std::set<std::string> common = {"name",         "type",      "verdict", "reason",
                                        "tolerance_mm", "points",    "min_mm",  "max_mm",
                                        "mean_mm",      "stddev_mm", "rms_mm",  "fraction_within"};
  std::set<std::string> area_keys = common, point_keys = common;
  area_keys.insert("allowed_fraction_outside");
  point_keys.insert("value_mm");
  EXPECT_EQ(Keys(j[0]), area_keys);
  EXPECT_EQ(Keys(j[1]), point_keys);
  EXPECT_EQ(j[0]["type"], "surface");
  EXPECT_EQ(j[0]["verdict"], "pass");
  EXPECT_EQ(j[0]["tolerance_mm"], (nlohmann::json{{"lower", -0.1}, {"upper", 0.2}}));
  EXPECT_EQ(j[0]["points"], 10);
  EXPECT_EQ(j[0]["min_mm"], -0.05);
  EXPECT_EQ(j[0]["rms_mm"], 0.03);
  EXPECT_EQ(j[0]["fraction_within"], 0.9);
  EXPECT_EQ(j[1]["type"], "point");
  EXPECT_EQ(j[1]["verdict"], "fail");
  EXPECT_TRUE(j[1]["value_mm"].is_null()) << "unmeasured";
  EXPECT_TRUE(j[1]["mean_mm"].is_null());
  EXPECT_EQ(j[1]["points"], 0);
}

TEST(PlanReport, DefectsCarryTheSchemaFields) {
  DefectsResult r;
  Defect d;
  d.id = 1;
  d.kind = DefectKind::kBump;
  d.centroid_mm = {1.5, -2, 60};
  d.area_mm2 = 12.5;
  d.extent_mm = 4;
  d.peak_mm = 0.25;
  d.points = 180;
  d.region = "ridge";
  r.defects = {d};
  const nlohmann::json j = DefectsJson(r);
  ASSERT_EQ(j.size(), 1u);
  EXPECT_EQ(Keys(j[0]), (std::set<std::string>{"id", "kind", "centroid_mm", "area_mm2", "extent_mm",
                                               "peak_mm", "points", "region"}));
  EXPECT_EQ(j[0]["id"], 1);
  EXPECT_EQ(j[0]["kind"], "bump");
  EXPECT_EQ(j[0]["centroid_mm"], (nlohmann::json{1.5, -2.0, 60.0}));
  EXPECT_EQ(j[0]["area_mm2"], 12.5);
  EXPECT_EQ(j[0]["extent_mm"], 4.0);
  EXPECT_EQ(j[0]["peak_mm"], 0.25);
  EXPECT_EQ(j[0]["points"], 180);
  EXPECT_EQ(j[0]["region"], "ridge");
  EXPECT_EQ(DefectsJson(DefectsResult{}), nlohmann::json::array());
}

}  // namespace
}  // namespace surfinspect
