// core/plan/plan_evaluation.cpp: the plan glue every caller runs, checked
// against the core functions it chains (ResolveInspectionPlan, FindDefects,
// ComputeCharacteristics) called directly, and the report/2 schema.
#include "core/plan/plan_evaluation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>

#include "core/io/io_mesh.h"
#include "core/pipeline/inspection_report.h"
#include "core/plan/surface_neighbourhood.h"
#include "tests/support/plane_scan.h"
#include "tests/support/temp_dir.h"
#include "tests/support/test_meshes.h"

namespace surfinspect {
namespace {

// The plane z = 0 over [0, 50]^2 scanned as a 160 x 160 grid at 0.25 mm
// pitch with noise 0.015 mm, a dent (-0.2 mm, sigma 2 mm) at (20, 20) and a
// bump (+0.15 mm, sigma 3 mm) at (35, 30).
struct Scene {
  TriangleMesh mesh;
  PointCloud cloud;
  ErrorMapResult error_map;
};

Scene MakeScene(const ErrorMapSettings& settings = {}) {
  Scene s;
  s.mesh = testing::HeightField(0, 50, 0, 50, 11, 11, [](double, double) { return 0.0; });
  std::mt19937_64 rng(5);
  s.cloud = testing::PlaneScan(160, 0.015, {{20, 20, -0.2, 2.0}, {35, 30, 0.15, 3.0}}, rng);
  auto index = MeshIndex::Build(s.mesh);
  EXPECT_TRUE(index.ok());
  auto em = ComputeErrorMap(**index, s.cloud, Eigen::Isometry3d::Identity(), settings);
  EXPECT_TRUE(em.ok()) << em.status();
  s.error_map = *std::move(em);
  return s;
}

// The scan covers [5, 44.75]^2 of the [0, 50]^2 square, with the 1 mm
// coverage distance [3.75, 45.75]^2: ~70% of the surface and of "left", so
// the plan asks for 60%.
nlohmann::json PlanJson() {
  return nlohmann::json::parse(R"({
    "min_coverage": 0.6,
    "regions": [{"name": "left", "select": {"box_mm": [[0, 0, -1], [25, 50, 1]]},
                 "tolerance_mm": {"lower": -0.25, "upper": 0.25}}],
    "points": [{"name": "dent", "position_mm": [20, 20, 0], "radius_mm": 1.0},
               {"name": "flat", "position_mm": [40, 10, 0]}],
    "defects": {"threshold_mm": 0.03, "min_area_mm2": 3.0}
  })");
}

TEST(PlanEvaluation, WithoutAPlanThePartVerdictIsTheToleranceVerdict) {
  for (double tol : {0.1, 0.3}) {
    ErrorMapSettings settings;
    settings.tolerance_mm = tol;
    const Scene s = MakeScene(settings);
    auto out = EvaluatePlan(s.error_map, s.cloud, s.mesh, PlanFromSettings(settings));
    ASSERT_TRUE(out.ok()) << out.status();
    EXPECT_EQ(out->pass(), s.error_map.verdict.pass) << tol;
    EXPECT_EQ(out->pass(), tol == 0.3) << "the dent is 0.2 mm deep";
    ASSERT_EQ(out->characteristics.characteristics.size(), 1u);
    const CharacteristicResult& surface = out->characteristics.characteristics[0];
    EXPECT_EQ(surface.name, "surface");
    EXPECT_EQ(surface.within, s.error_map.verdict.within);
    EXPECT_EQ(surface.points, s.error_map.stats.matched);
    EXPECT_FALSE(out->defects_run);
    EXPECT_TRUE(out->defects.defects.empty());
  }
}

TEST(PlanEvaluation, EqualsTheCoreFunctionsCalledDirectly) {
  const Scene s = MakeScene();
  auto plan = ParsePlanWithDefaults(PlanJson(), s.mesh, {});
  ASSERT_TRUE(plan.ok()) << plan.status();
  auto out = EvaluatePlan(s.error_map, s.cloud, s.mesh, *plan);
  ASSERT_TRUE(out.ok()) << out.status();
  auto resolved = ResolveInspectionPlan(*plan, s.mesh);
  ASSERT_TRUE(resolved.ok());
  auto defects = FindDefects(s.error_map, s.cloud, s.mesh, *plan->defects, &*resolved);
  ASSERT_TRUE(defects.ok());
  CoverageSettings cs;
  cs.distance_mm = kCoverageSpacings * EstimateSurfaceSpacing(s.error_map, s.cloud);
  auto coverage = ComputeCoverage(s.error_map, s.mesh, *resolved, cs);
  ASSERT_TRUE(coverage.ok());
  auto judged =
      ComputeCharacteristics(s.error_map, *resolved, defects->defects.size(), {}, &*coverage);
  ASSERT_TRUE(judged.ok());
  EXPECT_TRUE(out->defects_run);
  EXPECT_EQ(DefectsJson(out->defects), DefectsJson(*defects));
  EXPECT_EQ(CharacteristicsJson(out->characteristics), CharacteristicsJson(*judged));
  ASSERT_EQ(out->defects.defects.size(), 2u);
  EXPECT_EQ(out->defects.defects[0].kind, DefectKind::kDent);
  EXPECT_EQ(out->defects.defects[0].region, "left");
  EXPECT_EQ(out->defects.defects[1].region, "");
  // surface fails at +-0.1 (the dent), "left" passes at +-0.25, the dent's
  // comparison point reads the Gaussian's mean over a 1 mm disc,
  // -0.2 * 2 s^2 (1 - exp(-1 / (2 s^2))) at s = 2, and fails; the flat one passes.
  const auto& c = out->characteristics.characteristics;
  ASSERT_EQ(c.size(), 4u);
  EXPECT_FALSE(c[0].pass);
  EXPECT_TRUE(c[0].measured);
  EXPECT_NEAR(c[0].coverage, 41.75 * 41.75 / 2500, 0.005) << "[3.75, 45.75]^2";
  EXPECT_TRUE(c[1].pass) << c[1].reason;
  EXPECT_NEAR(c[2].value_mm, -0.2 * 8 * (1 - std::exp(-1.0 / 8)), 0.005);
  EXPECT_FALSE(c[2].pass);
  EXPECT_TRUE(c[3].pass) << c[3].reason;
  EXPECT_FALSE(out->pass());
}

TEST(PlanEvaluation, DefectsFailThePartOnlyWithMaxCount) {
  const Scene s = MakeScene();
  nlohmann::json j = PlanJson();
  j["tolerance_mm"] = {{"lower", -0.3}, {"upper", 0.3}};
  j["points"] = nlohmann::json::array();
  auto plan = ParsePlanWithDefaults(j, s.mesh, {});
  ASSERT_TRUE(plan.ok()) << plan.status();
  auto out = EvaluatePlan(s.error_map, s.cloud, s.mesh, *plan);
  ASSERT_TRUE(out.ok());
  EXPECT_EQ(out->defects.defects.size(), 2u);
  EXPECT_TRUE(out->pass()) << out->characteristics.reason;
  j["defects"]["max_count"] = 1;
  plan = ParsePlanWithDefaults(j, s.mesh, {});
  ASSERT_TRUE(plan.ok()) << plan.status();
  out = EvaluatePlan(s.error_map, s.cloud, s.mesh, *plan);
  ASSERT_TRUE(out.ok());
  EXPECT_FALSE(out->pass());
  EXPECT_EQ(out->characteristics.failed, 0u) << "every characteristic passes";
}

TEST(PlanEvaluation, TheSettingsAreThePlansDefaults) {
  const Scene s = MakeScene();
  ErrorMapSettings settings;
  settings.tolerance_mm = 0.25;
  settings.allowed_fraction_outside = 0.01;
  auto plan = ParsePlanWithDefaults(nlohmann::json::object(), s.mesh, settings);
  ASSERT_TRUE(plan.ok());
  EXPECT_EQ(plan->tolerance.lower_mm, -0.25);
  EXPECT_EQ(plan->tolerance.upper_mm, 0.25);
  EXPECT_EQ(plan->allowed_fraction_outside, 0.01);
  plan = ParsePlanWithDefaults(
      nlohmann::json::parse(R"({"tolerance_mm": {"lower": -0.05, "upper": 0.15},
                                "allowed_fraction_outside": 0})"),
      s.mesh, settings);
  ASSERT_TRUE(plan.ok());
  EXPECT_EQ(plan->tolerance.lower_mm, -0.05);
  EXPECT_EQ(plan->tolerance.upper_mm, 0.15);
  EXPECT_EQ(plan->allowed_fraction_outside, 0.0);
}

TEST(PlanEvaluation, BadPlansNameTheField) {
  const Scene s = MakeScene();
  nlohmann::json j = PlanJson();
  j["regions"][0]["select"]["box_mm"] = {{30, 0, -1}, {25, 50, 1}};
  auto plan = ParsePlanWithDefaults(j, s.mesh, {});
  ASSERT_EQ(plan.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(plan.status().message().substr(0, 26), "plan.regions[0].select.box") << plan.status();
  j = PlanJson();
  j["tolerance"] = 0.1;
  plan = ParsePlanWithDefaults(j, s.mesh, {});
  EXPECT_EQ(plan.status().message(), "plan.tolerance: unknown key");
  EXPECT_EQ(ParsePlanWithDefaults(nlohmann::json::array(), s.mesh, {}).status().code(),
            absl::StatusCode::kInvalidArgument);
  // A plan that does not fit the mesh is refused by EvaluatePlan too.
  InspectionPlan bad;
  bad.regions.push_back({"t", {}, {}, 0, {}});
  bad.regions[0].select.kind = RegionSelector::Kind::kTriangles;
  bad.regions[0].select.triangles = {static_cast<uint32_t>(s.mesh.num_triangles())};
  auto out = EvaluatePlan(s.error_map, s.cloud, s.mesh, bad);
  EXPECT_EQ(out.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(out.status().message().find("plan.regions[0].select.triangles[0]"), std::string::npos)
      << out.status();
}

// A section across the scan at x = 20 (through the dent), limited to the
// region "left" (x <= 25), judged on the points a brute-force selection
// finds; and sections a plan must refuse, naming the field.
TEST(PlanEvaluation, ASectionIsJudgedOnThePointsInItsSlab) {
  const Scene s = MakeScene();
  nlohmann::json j = PlanJson();
  j["sections"] = nlohmann::json::parse(R"([{"name": "S20", "point_mm": [20, 0, 0],
      "normal": [1, 0, 0], "width_mm": 0.5, "region": "left",
      "tolerance_mm": {"lower": -0.25, "upper": 0.25}}])");
  auto plan = ParsePlanWithDefaults(j, s.mesh, {});
  ASSERT_TRUE(plan.ok()) << plan.status();
  auto out = EvaluatePlan(s.error_map, s.cloud, s.mesh, *plan);
  ASSERT_TRUE(out.ok()) << out.status();
  const CharacteristicResult& c = out->characteristics.characteristics.back();
  EXPECT_EQ(c.name, "S20");
  EXPECT_EQ(c.type, CharacteristicType::kSection);
  std::size_t n = 0;
  double sum = 0, lo = INFINITY;
  for (std::size_t i = 0; i < s.error_map.triangle_id.size(); ++i) {
    const Eigen::Vector3f& q = s.error_map.closest_point[i];
    if (s.error_map.triangle_id[i] == UINT32_MAX || std::abs(q.x() - 20.0) > 0.25 || q.y() > 50)
      continue;
    ++n, sum += s.error_map.deviation_mm[i], lo = std::min<double>(lo, s.error_map.deviation_mm[i]);
  }
  EXPECT_EQ(c.points, n);
  EXPECT_NEAR(c.mean_mm, sum / static_cast<double>(n), 1e-12);
  EXPECT_EQ(c.min_mm, lo);
  EXPECT_LT(c.min_mm, -0.15) << "through the 0.2 mm dent";
  EXPECT_TRUE(c.pass) << c.reason;
  ASSERT_EQ(out->sections.size(), 1u);
  EXPECT_EQ(out->sections[0].points.size(), n);
  EXPECT_FALSE(out->sections[0].polylines.empty());
  for (const auto& [edit, field] : std::vector<std::pair<std::string, std::string>>{
           {R"({"point_mm": [80, 0, 0]})", "plan.sections[0]: the plane misses the part"},
           {R"({"width_mm": -1})", "plan.sections[0].width_mm: must be > 0"},
           {R"({"normal": [0, 0, 0]})", "plan.sections[0].normal: zero vector"},
           {R"({"region": "nowhere"})", "plan.sections[0].region: no region \"nowhere\""}}) {
    nlohmann::json b = j;
    b["sections"][0].merge_patch(nlohmann::json::parse(edit));
    EXPECT_EQ(ParsePlanWithDefaults(b, s.mesh, {}).status().message(), field);
  }
}

// A section's curve is judged like an area: its coverage is the share of
// the curve with a slab point within the coverage distance (brute force
// below, over every slab point for dense samples of the curve), and below
// the plan's min_coverage it is not measured.
TEST(PlanEvaluation, ASectionSeenOverLessOfItsCurveThanNeededIsNotMeasured) {
  const Scene s = MakeScene();
  nlohmann::json j = PlanJson();
  j["sections"] = nlohmann::json::parse(R"([{"name": "S20", "point_mm": [20, 0, 0],
      "normal": [1, 0, 0], "width_mm": 0.5, "tolerance_mm": {"lower": -0.25, "upper": 0.25}}])");
  for (double min_coverage : {0.6, 0.9}) {
    j["min_coverage"] = min_coverage;
    auto plan = ParsePlanWithDefaults(j, s.mesh, {});
    ASSERT_TRUE(plan.ok()) << plan.status();
    auto out = EvaluatePlan(s.error_map, s.cloud, s.mesh, *plan);
    ASSERT_TRUE(out.ok()) << out.status();
    const CharacteristicResult& c = out->characteristics.characteristics.back();
    const SectionCut& cut = out->sections[0];
    const double d = out->coverage.distance_mm;
    std::size_t seen = 0, samples = 0;
    for (double y = 0.0005; y < 50; y += 0.001, ++samples)
      for (uint32_t i : cut.points)
        if ((s.error_map.closest_point[i].cast<double>() - Eigen::Vector3d(20, y, 0)).norm() <= d) {
          ++seen;
          break;
        }
    const double truth = static_cast<double>(seen) / static_cast<double>(samples);
    EXPECT_NEAR(c.coverage, truth, 0.01);
    EXPECT_NEAR(truth, 0.84, 0.03) << "seen over y in [5 - d, 44.75 + d] of [0, 50]";
    EXPECT_EQ(c.measured, min_coverage < truth) << c.reason;
    if (!c.measured) {
      EXPECT_NE(c.reason.find("of its curve seen"), std::string::npos) << c.reason;
    }
  }
}

TEST(PlanEvaluation, ReportTwoKeepsTheErrorMapBlocksAndAddsTheResults) {
  const Scene s = MakeScene();
  auto plan = ParsePlanWithDefaults(PlanJson(), s.mesh, {});
  ASSERT_TRUE(plan.ok());
  auto out = EvaluatePlan(s.error_map, s.cloud, s.mesh, *plan);
  ASSERT_TRUE(out.ok());
  const nlohmann::json old = ErrorMapReportJson(s.error_map, {});
  const nlohmann::json j = EncodeReport(MakeInspectionReport(s.error_map, {}, *out));
  for (const auto& [key, value] : old.items()) EXPECT_EQ(j.at(key), value) << key;
  EXPECT_EQ(j.size(), old.size() + 5);  // schema, verdict, characteristics, defects, coverage
  EXPECT_TRUE(j.contains("coverage")) << "the plan judged coverage";
  EXPECT_EQ(j["schema"], "surfinspect.report/2");
  EXPECT_EQ(j["verdict"], "fail");
  EXPECT_EQ(j["characteristics"], CharacteristicsJson(out->characteristics));
  EXPECT_EQ(j["defects"], DefectsJson(out->defects));
  // Without a plan: the surface characteristic and an empty defects list.
  auto none = EvaluatePlan(s.error_map, s.cloud, s.mesh, PlanFromSettings({}));
  ASSERT_TRUE(none.ok());
  const nlohmann::json k = EncodeReport(MakeInspectionReport(s.error_map, {}, *none));
  EXPECT_EQ(k["verdict"], k["tolerance"]["verdict"]);
  ASSERT_EQ(k["characteristics"].size(), 1u);
  EXPECT_EQ(k["characteristics"][0]["name"], "surface");
  EXPECT_EQ(k["characteristics"][0]["tolerance_mm"]["lower"], -0.1);
  EXPECT_TRUE(k["defects"].is_array() && k["defects"].empty());
}

// A region that selects an OBJ group judges the same points as a box around
// the same triangles: the file's `g left` / `g right` split the plane at
// x = 25, where no triangle's centroid lies.
TEST(PlanEvaluation, GroupSelectorsOfAnObjFileJudgeTheirGroupsTriangles) {
  const Scene s = MakeScene();
  testing::TempDir dir;
  const std::string obj = dir.File("part.obj");
  {
    std::ofstream out(obj);
    for (const auto& v : s.mesh.vertices)
      out << "v " << v.x() << " " << v.y() << " " << v.z() << "\n";
    for (const char* side : {"left", "right"}) {
      out << "g " << side << "\n";
      for (const auto& t : s.mesh.triangles) {
        const double cx =
            (s.mesh.vertices[t[0]].x() + s.mesh.vertices[t[1]].x() + s.mesh.vertices[t[2]].x()) / 3;
        if ((cx < 25) == (std::string(side) == "left"))
          out << "f " << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << "\n";
      }
    }
  }
  auto part = ReadMesh(obj);
  ASSERT_TRUE(part.ok()) << part.status();
  auto index = MeshIndex::Build(*part);
  ASSERT_TRUE(index.ok());
  auto em = ComputeErrorMap(**index, s.cloud, Eigen::Isometry3d::Identity(), {});
  ASSERT_TRUE(em.ok());
  const auto plan_with = [&](const char* select) {
    auto plan = ParsePlanForMeshFile(
        nlohmann::json::parse(std::string(R"({"regions": [{"name": "left", "select": )") + select +
                              "}]}"),
        *part, obj, ErrorMapSettings{});
    EXPECT_TRUE(plan.ok()) << plan.status();
    return plan.ok() ? *plan : InspectionPlan{};
  };
  const InspectionPlan by_group = plan_with(R"({"group": "left"})");
  ASSERT_EQ(by_group.regions.size(), 1u);
  // The group is now triangle ids: a server needs no CAD file to apply it.
  EXPECT_EQ(by_group.regions[0].select.kind, RegionSelector::Kind::kTriangles);
  EXPECT_EQ(by_group.regions[0].select.triangles.size(), part->num_triangles() / 2);
  const InspectionPlan by_box = plan_with(R"({"box_mm": [[0, 0, -1], [25, 50, 1]]})");
  auto a = EvaluatePlan(*em, s.cloud, *part, by_group);
  auto b = EvaluatePlan(*em, s.cloud, *part, by_box);
  ASSERT_TRUE(a.ok() && b.ok());
  const CharacteristicResult& ra = a->characteristics.characteristics[1];
  const CharacteristicResult& rb = b->characteristics.characteristics[1];
  EXPECT_GT(ra.points, 1000u);
  EXPECT_EQ(ra.points, rb.points);
  EXPECT_EQ(ra.mean_mm, rb.mean_mm);
  EXPECT_EQ(ra.min_mm, rb.min_mm);

  auto unknown = ParsePlanForMeshFile(
      nlohmann::json::parse(R"({"regions": [{"name": "r", "select": {"group": "top"}}]})"), *part,
      obj, ErrorMapSettings{});
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.status().message().find("unknown group \"top\" (the part has 2 named groups)"),
            std::string::npos)
      << unknown.status();
}

}  // namespace
}  // namespace surfinspect
