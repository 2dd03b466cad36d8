// core/acceptance/artefacts.cpp: the round trip through the one writer, and
// every bad field named in its error.
#include "core/acceptance/artefacts.h"

#include <gtest/gtest.h>

namespace surfinspect {
namespace {

Artefacts Sample() {
  Artefacts a;
  a.sphere_diameter_mm = 25;
  a.sphere_diameter_u_mm = 0.0002;
  a.spheres = {{"sphere-1", {"v1", {1, 2, 3}}}};
  a.ball_bar_length_mm = 200;
  a.ball_bar_length_u_mm = 0.0005;
  a.ball_bar_sphere_diameter_mm = 25;
  a.ball_bar = {{"bb-1", {"v1", {0, 0, 0}}, {"v2", {200, 0, 0}}}};
  a.plate_flatness_u_mm = 0.0002;
  PlateMeasurement p;
  p.name = "plate-1";
  p.at = {"v3", {0, 0, 40}};
  p.normal = Eigen::Vector3d(0, 0.1, 1).normalized();
  p.radius_mm = 45;
  a.plates = {p};
  a.mpe = {0.12, 0.02, 0.02, 0.12};
  return a;
}

TEST(Artefacts, RoundTripThroughTheWriter) {
  const Artefacts a = Sample();
  auto b = ArtefactsFromJson(ArtefactsToJson(a), "artefacts.json");
  ASSERT_TRUE(b.ok()) << b.status();
  EXPECT_EQ(ArtefactsToJson(*b), ArtefactsToJson(a));
  EXPECT_TRUE(b->ball_bar[0].cross_view());
  EXPECT_DOUBLE_EQ(b->outlier_share, 0.003);
}

TEST(Artefacts, NegativeDiameterIsNamed) {
  nlohmann::json j = ArtefactsToJson(Sample());
  j["sphere"]["diameter_mm"] = -25.0;
  auto a = ArtefactsFromJson(j, "artefacts.json");
  ASSERT_EQ(a.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(a.status().message(), "artefacts.json: sphere.diameter_mm: must be > 0");
}

TEST(Artefacts, BadFieldsAreNamed) {
  const std::vector<std::pair<std::function<void(nlohmann::json&)>, std::string>> cases = {
      {[](auto& j) { j["ball_bar"]["length_mm"] = 0.0; }, "ball_bar.length_mm"},
      {[](auto& j) { j["mpe_mm"]["SD"] = -1.0; }, "mpe_mm.SD"},
      {[](auto& j) { j["mpe_mm"].erase("PF"); }, "mpe_mm.PF: missing"},
      {[](auto& j) { j["sphere"]["measurements"] = nlohmann::json::array(); }, "at least one"},
      {[](auto& j) {
         j["plate"]["measurements"][0]["normal"] = {0, 0, 0};
       },
       "plate-1.normal"},
      {[](auto& j) {
         j["ball_bar"]["positions"][0]["a"]["centre_mm"] = {1, 2};
       },
       "centre_mm"},
      {[](auto& j) { j["ball_bar"]["positions"][0]["name"] = "sphere-1"; }, "repeated name"},
      {[](auto& j) { j["outlier_share"] = 0.5; }, "outlier_share"},
      {[](auto& j) { j["schema"] = "x"; }, "schema"},
      {[](auto& j) { j["sphere"]["diameter_mm"] = "25"; }, "wrong type"},
  };
  for (const auto& [edit, expected] : cases) {
    nlohmann::json j = ArtefactsToJson(Sample());
    edit(j);
    auto a = ArtefactsFromJson(j, "a.json");
    ASSERT_FALSE(a.ok()) << expected;
    EXPECT_NE(a.status().message().find(expected), std::string::npos) << a.status();
    EXPECT_EQ(a.status().message().rfind("a.json: ", 0), 0u) << a.status();
  }
}

}  // namespace
}  // namespace surfinspect
