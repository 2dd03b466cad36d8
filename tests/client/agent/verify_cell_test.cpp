// The drift check (client/agent/verify_cell.cpp) on the demo cell with the
// simulated robot (client/agent/simulated_robot.cpp): a 20 µm drift of one
// viewpoint fails in 20 of 20 seeded runs and stops the agent, a 2 µm drift
// never fails; the status file, the metric and the clear errors.
#include "client/agent/verify_cell.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "client/agent/agent.h"
#include "client/agent/simulated_robot.h"
#include "client/cell/demo_cell_files.h"
#include "core/io/atomic_file.h"
#include "core/io/io_mesh.h"
#include "core/io/io_point_cloud.h"
#include "core/io/io_transform.h"
#include "proto/convert.h"
#include "tests/support/temp_dir.h"

namespace surfinspect::client {
namespace {
namespace fs = std::filesystem;

class VerifyCellTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new surfinspect::testing::TempDir;
    DemoWriteOptions o;
    o.parts = 0;
    o.acceptance = false;
    ASSERT_TRUE(WriteDemoCell(dir_->path() + "/cell", MakeDemoCell(), o).ok());
    auto cell = ReadCellConfig(dir_->path() + "/cell/cell.json");
    ASSERT_TRUE(cell.ok()) << cell.status();
    // Stored calibration: the robot's true pose (what a perfect calibrate finds).
    for (auto& vp : cell->viewpoints)
      for (const auto& jv : cell->raw["viewpoints"])
        if (jv["name"] == vp.name)
          vp.world_from_sensor =
              *TransformFromJsonValue(jv["simulation_truth_world_from_sensor"], "t");
    cell_ = new CellConfig(*std::move(cell));
    gauge_ = new TriangleMesh(*ReadMesh(cell_->gauge_mesh));
    index_ = MeshIndex::Build(*gauge_)->release();
  }
  static void TearDownTestSuite() {
    delete index_;
    delete gauge_;
    delete cell_;
    delete dir_;
  }

  // The cell with only viewpoint v2 (each seeded run is one scan and one fit).
  static CellConfig OneView() {
    CellConfig c = *cell_;
    c.viewpoints = {c.viewpoints[1]};
    return c;
  }
  static GaugeScanFn Robot(const CellConfig& cell, double drift_mm, uint64_t seed) {
    return [&cell, drift_mm, seed](const CellViewpoint& vp) {
      return SimulateGaugeScan(cell, *gauge_, vp, RobotDrift{"v2", drift_mm, seed}, seed);
    };
  }

  static surfinspect::testing::TempDir* dir_;
  static CellConfig* cell_;
  static TriangleMesh* gauge_;
  static MeshIndex* index_;
};
surfinspect::testing::TempDir* VerifyCellTest::dir_ = nullptr;
CellConfig* VerifyCellTest::cell_ = nullptr;
TriangleMesh* VerifyCellTest::gauge_ = nullptr;
MeshIndex* VerifyCellTest::index_ = nullptr;

TEST_F(VerifyCellTest, TwentyMicronDriftFailsInTwentyOfTwentySeededRuns) {
  const CellConfig cell = OneView();
  int fails = 0;
  double min_um = INFINITY, max_sigma = 0;
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    auto v = VerifyCell(cell, *index_, Robot(cell, 0.020, seed), DriftLimits{});
    ASSERT_TRUE(v.ok()) << v.status();
    ASSERT_TRUE(v->views[0].status.ok()) << v->views[0].status;
    fails += v->verdict == DriftClass::kFail;
    min_um = std::min(min_um, v->views[0].drift.at_part_um);
    max_sigma = std::max(max_sigma, v->views[0].drift.sigma_at_part_um);
  }
  std::printf("  20 um drift: %d of 20 fail; smallest move seen %.2f um, largest sigma %.2f um\n",
              fails, min_um, max_sigma);
  EXPECT_EQ(fails, 20);
}

TEST_F(VerifyCellTest, TwoMicronDriftNeverFailsInTwentyRuns) {
  const CellConfig cell = OneView();
  int fails = 0, warns = 0;
  double max_um = 0;
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    auto v = VerifyCell(cell, *index_, Robot(cell, 0.002, seed), DriftLimits{});
    ASSERT_TRUE(v.ok()) << v.status();
    ASSERT_TRUE(v->views[0].status.ok());
    fails += v->verdict == DriftClass::kFail;
    warns += v->verdict == DriftClass::kWarn;
    max_um = std::max(max_um, v->views[0].drift.at_part_um);
  }
  std::printf("  2 um drift: %d fail, %d warn of 20; largest move seen %.2f um\n", fails, warns,
              max_um);
  EXPECT_EQ(fails, 0);
}

TEST_F(VerifyCellTest, FailStopsTheAgentAndLeavesPartsInTheInbox) {
  const CellConfig cell = OneView();
  surfinspect::testing::TempDir tmp;
  const InboxLayout layout = ResolveLayout({tmp.path(), "", "", "", ""});
  ASSERT_TRUE(PrepareDirectories(layout).ok());
  for (const char* id : {"p1", "p2", "p3"}) {
    fs::create_directories(fs::path(layout.inbox) / id);
    ASSERT_TRUE(WritePointCloud((fs::path(layout.inbox) / id / "v2.pcd").string(),
                                PointCloud::Unorganized({{0, 0, 400}, {1, 0, 400}, {0, 1, 400}}))
                    .ok());
    ASSERT_TRUE(WriteStringAtomically((fs::path(layout.inbox) / id / "DONE").string(), "").ok());
  }
  VerifyConfig config;
  config.every_parts = 1;
  DriftMonitor monitor(config, [&] {
    auto v = VerifyCell(cell, *index_, Robot(cell, 0.020, 5), config.limits);
    if (v.ok()) {
      EXPECT_TRUE(WriteVerificationStatus(tmp.path(), cell, *v).ok());
    }
    return v;
  });
  AgentHooks hooks;
  int inspected = 0;
  hooks.inspect = [&](const v1::PartHeader& h, const std::vector<ViewScan>&) {
    ++inspected;
    v1::InspectResult r;
    r.set_part_id(h.part_id());
    r.set_verdict("pass");
    r.set_report_json(R"({"tolerance": {"band_mm": 0.3, "verdict": "pass"}, "color_range_mm": 1.0,)"
                      R"( "statistics": {"min_mm": 0, "max_mm": 0}})");
    wire::CloudToProto(PointCloud::Unorganized({{0, 0, 0}}), r.mutable_merged());
    r.set_deviations(wire::PackFloats({0.0f}));
    return absl::StatusOr<v1::InspectResult>(r);
  };
  hooks.sleep = [](double, const std::atomic<bool>&) {};
  hooks.before_part = [&](int done) { return monitor.BeforePart(done); };
  AgentSettings settings;
  settings.once = true;
  CellAgent agent(cell, layout, settings, hooks, 1);
  std::atomic<bool> stop{false};
  const RunSummary s = agent.Run(stop, nullptr);
  EXPECT_EQ(inspected, 1);  // p1, then the check before p2 fails
  EXPECT_NE(s.halted.find("calibration drift: v2"), std::string::npos) << s.halted;
  EXPECT_TRUE(fs::exists(fs::path(layout.inbox) / "p2"));
  EXPECT_TRUE(fs::exists(fs::path(layout.inbox) / "p3"));
  EXPECT_FALSE(monitor.BeforePart(5).ok());  // stays stopped
  auto status = ReadFileToString(tmp.path() + "/calibration_status.json");
  ASSERT_TRUE(status.ok());
  const auto j = nlohmann::json::parse(*status);
  EXPECT_EQ(j["state"], "fail");
  EXPECT_EQ(j["inspecting"], false);
  auto prom = ReadFileToString(tmp.path() + "/calibration_status.prom");
  ASSERT_TRUE(prom.ok());
  EXPECT_NE(
      prom->find("surfinspect_calibration_state{cell=\"" + cell.name + "\",viewpoint=\"v2\"} 2"),
      std::string::npos)
      << *prom;
}

TEST(DriftMonitor, ChecksEveryNPartsAndOnScheduleAndStaysStoppedAfterAFail) {
  auto now = std::chrono::steady_clock::time_point{};
  int checks = 0;
  DriftClass next = DriftClass::kOk;
  VerifyConfig config;
  config.every_parts = 3;
  config.every_s = 60;
  DriftMonitor m(
      config,
      [&]() -> absl::StatusOr<CellVerification> {
        ++checks;
        CellVerification v;
        v.verdict = next;
        v.reason = "v1: moved";
        return v;
      },
      [&] { return now; });
  EXPECT_TRUE(m.BeforePart(0).ok());
  EXPECT_TRUE(m.BeforePart(2).ok());
  EXPECT_EQ(checks, 0);
  EXPECT_TRUE(m.BeforePart(3).ok());  // 3 parts since the start
  EXPECT_EQ(checks, 1);
  EXPECT_TRUE(m.BeforePart(4).ok());
  now += std::chrono::seconds(61);  // the schedule, before 3 more parts
  next = DriftClass::kWarn;         // a warning does not stop
  EXPECT_TRUE(m.BeforePart(4).ok());
  EXPECT_EQ(checks, 2);
  next = DriftClass::kFail;
  const absl::Status st = m.BeforePart(7);
  EXPECT_EQ(checks, 3);
  EXPECT_EQ(st.code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_EQ(st.message(), "calibration drift: v1: moved");
  next = DriftClass::kOk;
  EXPECT_FALSE(m.BeforePart(8).ok());  // stays stopped until recalibrated and restarted
  EXPECT_EQ(checks, 3);
}

TEST_F(VerifyCellTest, VerifyWithoutStoredCalibrationIsAClearError) {
  CellConfig cell = OneView();
  cell.viewpoints[0].world_from_sensor.reset();
  int scans = 0;
  auto v = VerifyCell(
      cell, *index_,
      [&](const CellViewpoint&) -> absl::StatusOr<PointCloud> {
        ++scans;
        return PointCloud{};
      },
      DriftLimits{});
  ASSERT_EQ(v.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_EQ(v.status().message(),
            "viewpoint v2 has no stored calibration; run cell-agent calibrate first");
  EXPECT_EQ(scans, 0);
}

TEST_F(VerifyCellTest, UnreadableGaugeScanFailsTheViewNeverPasses) {
  const CellConfig cell = OneView();
  auto v = VerifyCell(
      cell, *index_,
      [](const CellViewpoint&) -> absl::StatusOr<PointCloud> {
        return absl::NotFoundError("v2.pcd: no such file");
      },
      DriftLimits{});
  ASSERT_TRUE(v.ok());
  EXPECT_EQ(v->verdict, DriftClass::kFail);
  EXPECT_NE(v->reason.find("cannot verify"), std::string::npos);
}

TEST_F(VerifyCellTest, ConfigAndRobotDriftAreParsedAndValidated) {
  CellConfig cell = OneView();
  cell.raw["verify"] = {{"every_parts", 10}, {"fail_um", 15.0}};
  auto c = VerifyConfigOf(cell);
  ASSERT_TRUE(c.ok()) << c.status();
  EXPECT_EQ(c->every_parts, 10);
  EXPECT_EQ(c->limits.fail_um, 15.0);
  cell.raw["verify"] = {{"warn_um", 20.0}};
  EXPECT_FALSE(VerifyConfigOf(cell).ok());
  auto d = ParseRobotDrift("v3:0.02");
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d->view, "v3");
  EXPECT_DOUBLE_EQ(d->mm, 0.02);
  for (const char* bad : {"v3", ":0.1", "v3:", "v3:x", "v3:-1"})
    EXPECT_FALSE(ParseRobotDrift(bad).ok()) << bad;
}

}  // namespace
}  // namespace surfinspect::client
