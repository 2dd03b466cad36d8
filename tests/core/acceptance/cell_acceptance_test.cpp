// core/acceptance/cell_acceptance.cpp on synthetic world-frame clouds (exact
// sphere caps and a plate): the figures, their MPE verdicts, the report's
// keys, and clear errors for an uncalibrated view or a missing scan.
#include "core/acceptance/cell_acceptance.h"

#include <gtest/gtest.h>

namespace surfinspect {
namespace {

void AddCap(std::vector<Eigen::Vector3f>& pts, const Eigen::Vector3d& c, double r) {
  for (int i = 0; i <= 40; ++i)
    for (int k = 0; k < 80; ++k) {
      const double polar = 1.2 * i / 40, az = 2 * M_PI * k / 80;
      pts.push_back((c + r * Eigen::Vector3d(std::sin(polar) * std::cos(az),
                                             std::sin(polar) * std::sin(az), std::cos(polar)))
                        .cast<float>());
    }
}

Artefacts Sample(double true_length) {
  Artefacts a;
  a.sphere_diameter_mm = 25;
  a.spheres = {{"sphere-1", {"v1", {0, 0, 50}}}};
  a.ball_bar_length_mm = 200;
  a.ball_bar_sphere_diameter_mm = 25;
  a.ball_bar = {{"bb-1", {"v1", {-100, 0, 50}}, {"v1", {100, 0, 50}}},
                {"bb-2", {"v1", {-100, 50, 50}}, {"v2", {-100 + true_length, 50, 50}}}};
  PlateMeasurement p;
  p.name = "plate-1";
  p.at = {"v2", {0, 0, 10}};
  p.radius_mm = 30;
  a.plates = {p};
  a.mpe = {0.01, 0.01, 0.02, 0.01};
  return a;
}

WorldScanFn Scans(double true_length) {
  return [true_length](const std::string& name,
                       const std::string& view) -> absl::StatusOr<PointCloud> {
    std::vector<Eigen::Vector3f> pts;
    if (name == "sphere-1") AddCap(pts, {0, 0, 50}, 12.5);
    if (name == "bb-1") AddCap(pts, {-100, 0, 50}, 12.5), AddCap(pts, {100, 0, 50}, 12.5);
    if (name == "bb-2" && view == "v1") AddCap(pts, {-100, 50, 50}, 12.5);
    if (name == "bb-2" && view == "v2") AddCap(pts, {-100 + true_length, 50, 50}, 12.5);
    if (name == "plate-1")
      for (int x = -40; x <= 40; ++x)
        for (int y = -40; y <= 40; ++y) pts.emplace_back(x, y, 10);
    if (pts.empty()) return absl::NotFoundError(name + "/" + view + ".pcd: no such scan");
    return PointCloud::Unorganized(std::move(pts));
  };
}

std::map<std::string, ViewCalibrationUncertainty> Views() { return {{"v1", {}}, {"v2", {}}}; }

TEST(CellAcceptance, ExactArtefactsPassAndTheReportHasEveryFigure) {
  auto r = RunAcceptance(Sample(200), Views(), Scans(200));
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_TRUE(r->pass);
  EXPECT_NEAR(r->pf.value_mm, 0, 1e-4);
  EXPECT_NEAR(r->ps.value_mm, 0, 1e-4);
  EXPECT_NEAR(r->f.value_mm, 0, 1e-4);
  ASSERT_EQ(r->sd.size(), 2u);
  const nlohmann::json j = AcceptanceReportJson(*r, Sample(200));
  for (const char* key : {"PF_mm", "PS_mm", "F_mm"})
    for (const char* field : {"value", "u", "U", "mpe", "pass"})
      EXPECT_TRUE(j[key].contains(field));
  ASSERT_EQ(j["SD_mm"].size(), 2u);
  EXPECT_EQ(j["SD_mm"][1]["cross_view"], true);
  EXPECT_EQ(j["verdict"], "pass");
  EXPECT_EQ(j["cross_view"]["positions"], 1);
}

TEST(CellAcceptance, ALongBarFailsSDAtItsPositionOnly) {
  auto r = RunAcceptance(Sample(200), Views(), Scans(200.03));
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_TRUE(r->sd[0].pass);
  EXPECT_FALSE(r->sd[1].pass);
  EXPECT_NEAR(r->sd[1].spacing.sd_mm, 0.03, 1e-4);
  EXPECT_FALSE(r->pass);
  EXPECT_EQ(AcceptanceReportJson(*r, Sample(200))["verdict"], "fail");
}

TEST(CellAcceptance, UncalibratedViewAndMissingScanAreClearErrors) {
  auto views = Views();
  views.erase("v2");
  auto r = RunAcceptance(Sample(200), views, Scans(200));
  ASSERT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("viewpoint v2"), std::string::npos);
  Artefacts a = Sample(200);
  a.plates[0].name = "plate-9";
  auto missing = RunAcceptance(a, Views(), Scans(200));
  ASSERT_EQ(missing.status().code(), absl::StatusCode::kNotFound);
  EXPECT_NE(missing.status().message().find("plate-9"), std::string::npos);
}

}  // namespace
}  // namespace surfinspect
