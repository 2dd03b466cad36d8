// Tests core/plan/inspection_plan.cpp (validation, resolution) and
// core/plan/inspection_plan_json.cpp (the JSON form).
#include "core/plan/inspection_plan.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <nlohmann/json.hpp>

#include "core/simulation/pillar.h"
#include "tests/support/test_meshes.h"

namespace surfinspect {
namespace {

using nlohmann::json;

// z = 0 over [0, 100]^2: 10 x 10 cells of 10 mm, 200 triangles.
TriangleMesh Plane() {
  return testing::HeightField(0, 100, 0, 100, 11, 11, [](double, double) { return 0.0; });
}

// Groups "left" (centroid x < 50) and "right".
MeshGroups LeftRight(const TriangleMesh& m) {
  MeshGroups g;
  g.names = {"left", "right"};
  for (const Triangle& t : m.triangles) {
    const double x = (m.vertices[t[0]].x() + m.vertices[t[1]].x() + m.vertices[t[2]].x()) / 3;
    g.triangle_group.push_back(x < 50 ? 0 : 1);
  }
  return g;
}

json GoodPlan() {
  return json::parse(R"({
    "schema": "surfinspect.plan/1",
    "tolerance_mm": {"lower": -0.1, "upper": 0.1},
    "regions": [
      {"name": "ridge", "select": {"box_mm": [[0, 20, -1], [100, 40, 1]]},
       "tolerance_mm": {"lower": -0.05, "upper": 0.15}, "allowed_fraction_outside": 0.01},
      {"name": "picked", "select": {"triangles": [5, 1, 3]}},
      {"name": "left", "select": {"group": "left"}}
    ],
    "points": [
      {"name": "P1", "position_mm": [50, 30, 0], "normal": [0, 0, 2], "radius_mm": 2.0,
       "tolerance_mm": {"lower": -0.1, "upper": 0.05}},
      {"name": "P2", "position_mm": [10, 10, 0]}
    ],
    "defects": {"threshold_mm": 0.05, "min_area_mm2": 3.0, "max_count": 0}
  })");
}

TEST(InspectionPlan, ParsesTheDocumentedExample) {
  const TriangleMesh m = Plane();
  auto plan = ParseInspectionPlan(GoodPlan(), m, "plan", LeftRight(m));
  ASSERT_TRUE(plan.ok()) << plan.status();
  EXPECT_EQ(plan->tolerance.lower_mm, -0.1);
  ASSERT_EQ(plan->regions.size(), 3u);
  EXPECT_EQ(plan->regions[0].select.kind, RegionSelector::Kind::kBox);
  EXPECT_EQ(plan->regions[0].select.box_max_mm, Eigen::Vector3d(100, 40, 1));
  EXPECT_EQ(plan->regions[0].tolerance->upper_mm, 0.15);
  EXPECT_EQ(plan->regions[0].allowed_fraction_outside, 0.01);
  EXPECT_EQ(plan->regions[1].select.triangles, (std::vector<uint32_t>{5, 1, 3}));
  EXPECT_FALSE(plan->regions[1].tolerance.has_value()) << "unset: the plan's default";
  EXPECT_EQ(plan->regions[2].select.group, "left");
  ASSERT_EQ(plan->points.size(), 2u);
  EXPECT_EQ(plan->points[0].normal, Eigen::Vector3d(0, 0, 1)) << "normalised";
  EXPECT_EQ(plan->points[1].radius_mm, 2.0) << "default radius";
  ASSERT_TRUE(plan->defects.has_value());
  EXPECT_EQ(plan->defects->max_count, 0);
  // Minimal plans: {} is the default band over the surface alone.
  auto empty = ParseInspectionPlan(json::object(), m);
  ASSERT_TRUE(empty.ok()) << empty.status();
  EXPECT_TRUE(empty->regions.empty());
  EXPECT_FALSE(empty->defects.has_value());
}

// Each refusal: an edit of the good plan, and the start of the message.
struct Refusal {
  const char* what;
  std::function<void(json&)> edit;
  const char* message;
};

TEST(InspectionPlan, RefusesBadPlansNamingTheField) {
  const TriangleMesh m = Plane();
  const std::vector<Refusal> cases = {
      {"unknown top-level key", [](json& j) { j["tolerance"] = 0.1; },
       "plan.tolerance: unknown key"},
      {"unknown region key", [](json& j) { j["regions"][0]["colour"] = "red"; },
       "plan.regions[0].colour: unknown key"},
      {"unknown selector",
       [](json& j) {
         j["regions"][1]["select"] = {{"sphere", 1}};
       },
       "plan.regions[1].select.sphere: unknown key"},
      {"unknown tolerance key", [](json& j) { j["tolerance_mm"]["nominal"] = 0; },
       "plan.tolerance_mm.nominal: unknown key"},
      {"empty box", [](json& j) { j["regions"][0]["select"]["box_mm"][1][2] = -1; },
       "plan.regions[0].select.box_mm: empty or inverted box"},
      {"inverted box", [](json& j) { j["regions"][0]["select"]["box_mm"][1][0] = -5; },
       "plan.regions[0].select.box_mm: empty or inverted box"},
      {"lower > upper", [](json& j) { j["points"][0]["tolerance_mm"]["lower"] = 0.06; },
       "plan.points[0].tolerance_mm: lower (0.06) > upper (0.05)"},
      {"non-finite tolerance", [](json& j) { j["tolerance_mm"]["upper"] = INFINITY; },
       "plan.tolerance_mm.upper: not a finite number"},
      {"non-finite position", [](json& j) { j["points"][1]["position_mm"][1] = NAN; },
       "plan.points[1].position_mm[1]: not a finite number"},
      {"unknown group", [](json& j) { j["regions"][2]["select"]["group"] = "middle"; },
       "plan.regions[2].select.group: unknown group \"middle\""},
      {"triangle id out of range", [](json& j) { j["regions"][1]["select"]["triangles"][2] = 200; },
       "plan.regions[1].select.triangles[2]: triangle id 200 out of range"},
      {"negative triangle id", [](json& j) { j["regions"][1]["select"]["triangles"][0] = -1; },
       "plan.regions[1].select.triangles[0]: triangle id must be an integer"},
      {"duplicate region names", [](json& j) { j["regions"][1]["name"] = "ridge"; },
       "plan.regions[1].name: duplicate name \"ridge\""},
      {"region and point share a name", [](json& j) { j["points"][0]["name"] = "left"; },
       "plan.points[0].name: duplicate name \"left\""},
      {"reserved name", [](json& j) { j["points"][1]["name"] = "surface"; },
       "plan.points[1].name: \"surface\" is reserved"},
      {"wrong type", [](json& j) { j["points"][0]["radius_mm"] = "2"; },
       "plan.points[0].radius_mm: must be a number"},
      {"zero radius", [](json& j) { j["points"][0]["radius_mm"] = 0; },
       "plan.points[0].radius_mm: must be > 0"},
      {"fraction above 1", [](json& j) { j["regions"][0]["allowed_fraction_outside"] = 1.5; },
       "plan.regions[0].allowed_fraction_outside: must be in [0, 1]"},
      {"two selectors", [](json& j) { j["regions"][0]["select"]["group"] = "left"; },
       "plan.regions[0].select: needs exactly one of"},
      {"missing name", [](json& j) { j["regions"][0].erase("name"); },
       "plan.regions[0].name: missing"},
      {"zero threshold", [](json& j) { j["defects"]["threshold_mm"] = 0; },
       "plan.defects.threshold_mm: must be > 0"},
      {"other schema", [](json& j) { j["schema"] = "surfinspect.plan/2"; },
       "plan.schema: unsupported"},
  };
  for (const Refusal& c : cases) {
    json j = GoodPlan();
    c.edit(j);
    auto plan = ParseInspectionPlan(j, m, "plan", LeftRight(m));
    ASSERT_FALSE(plan.ok()) << c.what;
    EXPECT_EQ(plan.status().code(), absl::StatusCode::kInvalidArgument) << c.what;
    EXPECT_EQ(std::string(plan.status().message()).rfind(c.message, 0), 0u)
        << c.what << ": got \"" << plan.status().message() << "\"";
  }
  // Without the mesh's groups, a group selector cannot resolve.
  auto no_groups = ParseInspectionPlan(GoodPlan(), m);
  ASSERT_FALSE(no_groups.ok());
  EXPECT_EQ(std::string(no_groups.status().message()).rfind("plan.regions[2].select.group", 0), 0u);
}

TEST(InspectionPlan, TheValidatorChecksStructsFromAnySource) {
  const TriangleMesh m = Plane();
  InspectionPlan plan;
  EXPECT_TRUE(ValidateInspectionPlan(plan, m).ok());
  plan.tolerance = {0.2, 0.1};
  auto st = ValidateInspectionPlan(plan, m, {}, "ErrorMapRequest.plan");
  EXPECT_EQ(st.message(), "ErrorMapRequest.plan.tolerance_mm: lower (0.2) > upper (0.1)");
  plan.tolerance = {-0.1, 0.1};
  plan.points.push_back({"P", Eigen::Vector3d(1, 2, NAN), Eigen::Vector3d::Zero(), 2.0, {}, {}});
  EXPECT_EQ(ValidateInspectionPlan(plan, m).message(),
            "plan.points[0].position_mm: not a finite number");
  plan.points[0].position_mm.z() = 0;
  plan.points[0].radius_mm = NAN;
  EXPECT_EQ(ValidateInspectionPlan(plan, m).message(),
            "plan.points[0].radius_mm: not a finite number");
  MeshGroups short_groups;
  short_groups.names = {"a"};
  short_groups.triangle_group = {0, 0};
  plan.points.clear();
  EXPECT_FALSE(ValidateInspectionPlan(plan, m, short_groups).ok()) << "groups must cover the part";
}

TEST(InspectionPlan, ResolvesMembershipAgainstBruteForce) {
  const TriangleMesh m = Plane();
  const MeshGroups groups = LeftRight(m);
  auto plan = ParseInspectionPlan(GoodPlan(), m, "plan", groups);
  ASSERT_TRUE(plan.ok()) << plan.status();
  auto r = ResolveInspectionPlan(*plan, m, groups);
  ASSERT_TRUE(r.ok()) << r.status();
  ASSERT_EQ(r->region_offsets.size(), m.num_triangles() + 1);
  std::size_t in_box = 0, overlap = 0;
  for (uint32_t t = 0; t < m.num_triangles(); ++t) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) c += m.vertices[m.triangles[t][k]].cast<double>() / 3;
    std::vector<uint32_t> want;
    if (c.y() >= 20 && c.y() <= 40) want.push_back(0);  // the box spans x and z fully
    if (t == 1 || t == 3 || t == 5) want.push_back(1);
    if (c.x() < 50) want.push_back(2);
    const std::vector<uint32_t> got(r->region_ids.begin() + r->region_offsets[t],
                                    r->region_ids.begin() + r->region_offsets[t + 1]);
    EXPECT_EQ(got, want) << "triangle " << t;
    in_box += !want.empty() && want[0] == 0;
    overlap += want.size() > 1;
    EXPECT_EQ(r->FirstRegionOf(t), want.empty() ? -1 : static_cast<int>(want[0]));
  }
  EXPECT_GT(in_box, 0u);
  EXPECT_GT(overlap, 0u) << "regions overlap";
  EXPECT_EQ(r->region_triangle_count[1], 3u);
  EXPECT_EQ(r->region_triangle_count[2], 100u);
  // A triangle reaches a comparison point when any of it is within the radius.
  for (uint32_t t = 0; t < m.num_triangles(); ++t)
    for (uint32_t p = 0; p < plan->points.size(); ++p) {
      const auto& tri = m.triangles[t];
      const double d = testing::DistanceByProjection(
          plan->points[p].position_mm, m.vertices[tri[0]].cast<double>(),
          m.vertices[tri[1]].cast<double>(), m.vertices[tri[2]].cast<double>());
      const bool listed = std::count(r->point_ids.begin() + r->point_offsets[t],
                                     r->point_ids.begin() + r->point_offsets[t + 1], p) > 0;
      EXPECT_EQ(listed, d <= plan->points[p].radius_mm) << "triangle " << t << " point " << p;
    }
}

// Holes, slots and edge points on the pillar that has them: the entries
// `surfinspect holes --plan` prints parse; each bad value is refused naming
// its field.
TEST(InspectionPlan, HolesSlotsAndEdgePointsAreCheckedAgainstTheCad) {
  const TriangleMesh part = MakePillarMesh(300, DemoPillarFeatures());
  json j = PlanHolesJson(ListHoles(part), 0.25);
  j["edge_points"] = {{{"name", "end"}, {"position_mm", {150, 0, 57}}}};
  auto plan = ParseInspectionPlan(j, part);
  ASSERT_TRUE(plan.ok()) << plan.status();
  ASSERT_EQ(plan->holes.size(), 6u);
  EXPECT_TRUE(plan->holes[5].slot) << "slots after holes";
  EXPECT_EQ(plan->holes[5].name, "S1");
  EXPECT_EQ(plan->holes[0].position_tolerance_mm, 0.25);
  EXPECT_EQ(plan->edge_points[0].radius_mm, 5.0) << "the default";
  const std::vector<std::pair<std::function<void(json&)>, std::string>> bad = {
      {[](json& p) {
         p["holes"][0]["position_mm"] = {0, 0, 60};
       },
       "plan.holes[0].position_mm: no hole of the CAD there (6 found: boundary loops or solid "
       "rims that are circles or slots)"},
      {[](json& p) {
         p["holes"][1]["axis"] = {0, 0, 0};
       },
       "plan.holes[1].axis: zero vector"},
      {[](json& p) { p["holes"][0]["diameter_mm"] = -8; },
       "plan.holes[0].diameter_mm: must be > 0"},
      {[](json& p) { p["slots"][0]["length_mm"] = 5; },
       "plan.slots[0].length_mm: must be > width_mm"},
      {[](json& p) {
         p["slots"][0]["direction"] = {0, 0, 1};
       },
       "plan.slots[0].direction: must be a finite vector across the axis"},
      {[](json& p) { p["slots"][0].erase("direction"); }, "plan.slots[0].direction: missing"},
      {[](json& p) { p["holes"][0]["depth_mm"] = 1; }, "plan.holes[0].depth_mm: unknown key"},
      {[](json& p) { p["holes"][2]["name"] = "H1"; },
       "plan.holes[2].name: duplicate name \"H1\" (characteristics share one namespace)"},
      {[](json& p) {
         p["edge_points"][0]["position_mm"] = {0, 0, 60};
       },
       "plan.edge_points[0].position_mm: the CAD's boundary is 20.8 mm away, farther than "
       "radius_mm"},  // the edge of the 5 mm hole at (-20, -12)
      {[](json& p) { p["edge_points"][0]["radius_mm"] = 0; },
       "plan.edge_points[0].radius_mm: must be > 0"}};
  for (const auto& [edit, message] : bad) {
    json b = j;
    edit(b);
    EXPECT_EQ(ParseInspectionPlan(b, part).status().message(), message);
  }
}

}  // namespace
}  // namespace surfinspect
