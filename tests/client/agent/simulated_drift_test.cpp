// The simulated robot's process drift, found again by the trend: 30 parts of
// a small-sensor demo cell scanned with `bow:0.005` (the ridge rises 5 um per
// part, noise 0.015 mm), inspected in-process, written as part outputs,
// recorded from their files into SQLite exactly as the agent records them;
// then the fitted slope and the trend map must show the drift, and 30 parts
// without drift must stay within the rules' false-alarm rate. And parts
// placed off in their fixture, with their truth.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "client/agent/simulated_robot.h"
#include "client/cell/demo_cell_files.h"
#include "client/cell/part_outputs.h"
#include "client/cell/part_recorder.h"
#include "core/history/trend.h"
#include "core/io/atomic_file.h"
#include "core/io/io_mesh.h"
#include "core/io/io_point_cloud.h"
#include "tests/support/temp_dir.h"

namespace surfinspect::client {
namespace {
namespace fs = std::filesystem;
using surfinspect::testing::TempDir;

// The demo cell with a 128 x 96 sensor, calibrated at the simulation's true
// poses.
CellConfig SmallCell(const std::string& dir) {
  DemoCell demo = MakeDemoCell();
  demo.intrinsics.width = 128;
  demo.intrinsics.height = 96;
  EXPECT_TRUE(WriteDemoCell(dir, demo, {0, {}}).ok());
  nlohmann::json j = nlohmann::json::parse(std::ifstream(dir + "/cell.json"));
  for (auto& vp : j["viewpoints"])
    vp["world_from_sensor"] = vp["simulation_truth_world_from_sensor"];
  j["name"] = "drift-cell";
  // Mixed pixels at this pitch survive any filter that keeps the walls whole
  // and sit 0.5-5 mm off the CAD on the ridge's shoulders; they would be the
  // map's largest means. Noise 0.015 mm and pulses stay.
  j["simulation"] = {{"stripes", false}};
  // The filter's link distance scaled with the pixel pitch (1024 / 128 times
  // the demo sensor's), so surfaces stay whole and pulses stay alone.
  j["filter"] = {{"link_distance_mm", 4.0}, {"min_cluster_points", 20}};
  // Pulses near the ridge's edges that land within 5 mm of a wall would bias
  // those triangles' means (measured: +0.066 mm, sigma 0.2-0.36 mm); the
  // drift and the defects are all within 1 mm.
  j["error_map"]["max_distance_mm"] = 1.0;
  EXPECT_TRUE(WriteStringAtomically(dir + "/cell.json", j.dump(2)).ok());
  // The drift is on the surface. At this pitch (2 mm) the demo's 5-12 mm
  // holes are a few pixels across, below what their edges resolve: the plan
  // judges the surface, its regions, points and section only.
  nlohmann::json plan = nlohmann::json::parse(std::ifstream(dir + "/plan.json"));
  for (const char* key : {"holes", "slots", "edge_points"}) plan.erase(key);
  EXPECT_TRUE(WriteStringAtomically(dir + "/plan.json", plan.dump(2)).ok());
  auto cell = ReadCellConfig(dir + "/cell.json");
  EXPECT_TRUE(cell.ok()) << cell.status();
  return *cell;
}

// Simulates, inspects, writes and records `n` parts; returns the trend.
Trend RunParts(const std::string& dir, const CellConfig& cell, int n, const SurfaceDrift& drift,
               uint64_t seed) {
  auto ids = SimulateParts(cell, dir + "/inbox", n, seed, drift);
  EXPECT_TRUE(ids.ok()) << ids.status();
  const TriangleMesh part = *ReadMesh(cell.part_mesh);
  std::shared_ptr<const MeshIndex> index = *MeshIndex::Build(part);
  InspectionSettings settings = InspectionSettingsOf(cell);
  settings.plan = *PlanOf(cell, part, settings.error_map);
  auto store = OpenResultsStore(dir + "/results.db");
  EXPECT_TRUE(store.ok()) << store.status();
  const RecordContext context = RecordContextOf(cell, index);
  for (const std::string& id : *ids) {
    std::vector<ViewScan> views;
    for (const CellViewpoint& vp : cell.viewpoints)
      views.push_back({vp.name, *ReadPointCloud(dir + "/inbox/" + id + "/" + vp.name + ".pcd"),
                       *vp.world_from_sensor});
    auto r = InspectPart(*index, cell.world_from_part, std::move(views), settings);
    EXPECT_TRUE(r.ok()) << r.status();
    auto outputs = OutputsFromLocal(id, *r, settings, cell.world_from_part, part);
    EXPECT_TRUE(WritePartOutputs(dir + "/results/" + id, *outputs).ok());
    auto written = RecordPartFromFiles(**store, context, id, dir + "/results/" + id);
    EXPECT_TRUE(written.ok() && *written) << written.status();
  }
  PartSelection sel;
  sel.cell = "drift-cell";
  sel.with_triangles = true;
  auto parts = (*store)->Load(sel);
  EXPECT_EQ(parts->size(), static_cast<std::size_t>(n));
  return *ComputeTrend(*parts);
}

const CharacteristicTrend& Named(const Trend& t, const std::string& name) {
  for (const CharacteristicTrend& c : t.characteristics)
    if (c.name == name) return c;
  ADD_FAILURE() << "no characteristic " << name;
  return t.characteristics.front();
}

TEST(SimulatedDrift, BowOnTheRidgeIsFoundBySlopeAndTrendMap) {
  TempDir dir;
  const CellConfig cell = SmallCell(dir.path());
  const SurfaceDrift drift = *ParseSurfaceDrift("bow:0.005");
  const Trend trend = RunParts(dir.path(), cell, 30, drift, 5);
  // The truth beside the last part: 29 steps of 5 um.
  auto truth = nlohmann::json::parse(std::ifstream(dir.File("inbox/sim-0005-0030/truth.json")));
  EXPECT_NEAR(truth["drift"]["height_mm"].get<double>(), 0.145, 1e-12);
  const CharacteristicTrend& centre = Named(trend, "ridge-centre");
  ASSERT_TRUE(centre.drift);
  EXPECT_NEAR(centre.drift->slope_mm_per_part, 0.005, 0.15 * 0.005);
  EXPECT_LT(centre.drift->ci_lower, 0.005 * 1.15);
  EXPECT_GT(centre.drift->ci_upper, 0.005 * 0.85);
  EXPECT_FALSE(centre.violations.empty());
  // The trend map's largest mean lies on the bump (centre (0, 0), R = 40 mm).
  ASSERT_GE(trend.map.largest, 0);
  const TriangleTrend& top = trend.map.triangles[trend.map.largest];
  const TriangleMesh part = *ReadMesh(cell.part_mesh);
  const auto& tri = part.triangles[top.triangle_id];
  const Eigen::Vector3f c =
      (part.vertices[tri[0]] + part.vertices[tri[1]] + part.vertices[tri[2]]) / 3;
  EXPECT_LT(std::hypot(c.x(), c.y()), 40.0) << "triangle " << top.triangle_id;
  std::printf(
      "ridge-centre slope %+.6f [%+.6f, %+.6f] mm/part, %zu flags; map top triangle %u "
      "at (%.1f, %.1f) mean %.4f sigma %.4f mm\n",
      centre.drift->slope_mm_per_part, centre.drift->ci_lower, centre.drift->ci_upper,
      centre.violations.size(), top.triangle_id, c.x(), c.y(), top.mean_mm, top.sigma_mm);
  EXPECT_GT(top.mean_mm, 0.04);  // the mean over 30 parts of 0..0.145 mm is 0.0725 at the top
}

// Without drift: the slope's interval holds 0 and the rules fire no more
// often than their false-alarm rate (about 0.010 flagged points per part and
// characteristic, western_electric_test.cpp), i.e. about 1.5 flags over the
// 5 characteristics of 30 parts; more than 6 would have a probability below
// 0.5% under that rate.
TEST(SimulatedDrift, NoDriftNoAlarm) {
  TempDir dir;
  const CellConfig cell = SmallCell(dir.path());
  const Trend trend = RunParts(dir.path(), cell, 30, {}, 6);
  std::size_t flags = 0;
  for (const CharacteristicTrend& c : trend.characteristics) {
    flags += c.violations.size();
    ASSERT_TRUE(c.drift) << c.name;
    std::printf("%-14s slope %+.6f [%+.6f, %+.6f] mm/part, %zu flags\n", c.name.c_str(),
                c.drift->slope_mm_per_part, c.drift->ci_lower, c.drift->ci_upper,
                c.violations.size());
    EXPECT_LT(std::abs(c.drift->slope_mm_per_part), 0.001) << c.name;
  }
  EXPECT_LE(flags, 6u);
}

TEST(SimulatedDrift, SpecsAreParsedAndBadOnesNamed) {
  const SurfaceDrift shift = *ParseSurfaceDrift("shift:0.05@10:20,5,30");
  EXPECT_EQ(shift.HeightAt(8), 0.0);   // part 9
  EXPECT_EQ(shift.HeightAt(9), 0.05);  // part 10
  EXPECT_EQ(shift.radius_mm, 30);
  EXPECT_EQ(ParseSurfaceDrift("bow:0.002")->HeightAt(3), 0.006);
  for (const char* bad : {"bow", "bow:x", "wobble:1", "shift:0.05", "bow:0.1:1,2", "bow:1@3"}) {
    const absl::Status st = ParseSurfaceDrift(bad).status();
    EXPECT_NE(st.message().find(bad), std::string::npos) << st;
  }
}

}  // namespace
}  // namespace surfinspect::client

namespace surfinspect::client {
namespace {

// --fixture-error: each part sits off in its fixture by at most MM and MM/2
// degrees, its truth in truth.json; its scans move with it (the same seed
// without the error scans the part where the CAD says).
TEST(SimulatedFixture, EachPartSitsOffWithinTheBoundAndItsTruthIsWritten) {
  TempDir dir;
  const CellConfig cell = SmallCell(dir.path());
  auto ids = SimulateParts(cell, dir.path() + "/inbox", 4, 7, {}, {}, 0, 1.0);
  ASSERT_TRUE(ids.ok()) << ids.status();
  auto plain = SimulateParts(cell, dir.path() + "/plain", 1, 7);
  ASSERT_TRUE(plain.ok()) << plain.status();
  for (const std::string& id : *ids) {
    const nlohmann::json truth =
        nlohmann::json::parse(std::ifstream(dir.path() + "/inbox/" + id + "/truth.json"));
    ASSERT_TRUE(truth.contains("fixture")) << truth.dump();
    const nlohmann::json& f = truth["fixture"];
    ASSERT_EQ(f["in_fixture"].size(), 16u);
    const Eigen::Vector3d t(f["translation_mm"][0], f["translation_mm"][1], f["translation_mm"][2]);
    EXPECT_LE(t.norm(), 1.0 + 1e-12);
    EXPECT_LE(f["rotation_deg"].get<double>(), 0.5 + 1e-12);
    EXPECT_EQ(f["in_fixture"][15], 1.0);
    EXPECT_EQ(f["in_fixture"][3], t.x()) << "row-major: the translation is the last column";
  }
  const std::string view = cell.viewpoints[0].name + ".pcd";
  const PointCloud off = *ReadPointCloud(dir.path() + "/inbox/" + (*ids)[0] + "/" + view);
  const PointCloud at = *ReadPointCloud(dir.path() + "/plain/" + (*plain)[0] + "/" + view);
  ASSERT_EQ(off.size(), at.size());
  double moved = 0;
  for (std::size_t i = 0; i < off.size(); ++i)
    if (PointCloud::IsValid(off.points[i]) && PointCloud::IsValid(at.points[i]))
      moved = std::max(moved, double((off.points[i] - at.points[i]).norm()));
  EXPECT_GT(moved, 0.05) << "the displaced part's scan did not move";
}

}  // namespace
}  // namespace surfinspect::client
