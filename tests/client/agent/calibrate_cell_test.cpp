#include "client/agent/calibrate_cell.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "core/io/io_point_cloud.h"
#include "proto/convert.h"
#include "tests/support/temp_dir.h"

namespace surfinspect::client {
namespace {
using surfinspect::testing::ReadBytes;
using surfinspect::testing::TempDir;
using surfinspect::testing::WriteBytes;

// Two viewpoints; v1 has a gauge scan, v2's is missing.
CellConfig TwoViewCell(const TempDir& tmp) {
  CellConfig cell;
  cell.path = tmp.File("cell.json");
  cell.raw = nlohmann::json::parse(R"({"viewpoints": [{"name": "v1"}, {"name": "v2"}]})");
  WriteBytes(cell.path, cell.raw.dump());
  for (const char* name : {"v1", "v2"}) {
    CellViewpoint vp;
    vp.name = name;
    vp.gauge_scan = tmp.File(std::string(name) + ".pcd");
    cell.viewpoints.push_back(vp);
  }
  EXPECT_TRUE(
      WritePointCloud(cell.viewpoints[0].gauge_scan, PointCloud::Unorganized({{0, 0, 1}})).ok());
  return cell;
}

TEST(CalibrateCellTest, RetriesThenStoresPoseAndQuality) {
  TempDir tmp;
  CellConfig cell = TwoViewCell(tmp);
  int calls = 0;
  const auto calibrate =
      [&](const v1::CalibrateRequest& req) -> absl::StatusOr<v1::CalibrateResponse> {
    EXPECT_EQ(req.scan().width(), 1u);
    if (++calls == 1) return absl::UnavailableError("down");
    CalibrationResult r;
    r.world_from_sensor.translation() = Eigen::Vector3d(1, 2, 3);
    r.rms_mm = 0.02;
    v1::CalibrateResponse resp;
    wire::CalibrationToProto(r, &resp);
    return resp;
  };
  CalibrateCellOptions options;
  int waits = 0, retries = 0;
  options.sleep = [&](double, const std::atomic<bool>&) { ++waits; };
  options.on_retry = [&](const std::string& view, const absl::Status&, int, double) {
    EXPECT_EQ(view, "v1");
    ++retries;
  };
  std::vector<std::string> seen;
  options.on_view = [&](const ViewCalibration& v) { seen.push_back(v.name); };
  std::atomic<bool> stop{false};
  const auto views = CalibrateCell(cell, calibrate, options, stop);
  ASSERT_EQ(views.size(), 2u);
  EXPECT_EQ(seen, (std::vector<std::string>{"v1", "v2"}));
  EXPECT_TRUE(views[0].status.ok()) << views[0].status;
  EXPECT_FALSE(views[1].status.ok());  // no gauge scan: no call
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(waits, 1);
  EXPECT_EQ(retries, 1);
  ASSERT_TRUE(cell.viewpoints[0].world_from_sensor.has_value());
  EXPECT_TRUE(
      cell.viewpoints[0].world_from_sensor->translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_FALSE(cell.viewpoints[1].world_from_sensor.has_value());

  ASSERT_TRUE(StoreCalibrations(cell, views).ok());
  const auto j = nlohmann::json::parse(ReadBytes(cell.path));
  EXPECT_EQ(j["viewpoints"][0]["calibration"]["rms_mm"].get<double>(), 0.02);
  EXPECT_TRUE(j["viewpoints"][0].contains("world_from_sensor"));
  EXPECT_FALSE(j["viewpoints"][1].contains("calibration"));
  EXPECT_EQ(ReadBytes(cell.path + ".bak"), cell.raw.dump());
}

TEST(CalibrateCellTest, StopMakesNoFurtherCalls) {
  TempDir tmp;
  CellConfig cell = TwoViewCell(tmp);
  int calls = 0;
  std::atomic<bool> stop{true};
  const auto views = CalibrateCell(
      cell,
      [&](const v1::CalibrateRequest&) -> absl::StatusOr<v1::CalibrateResponse> {
        ++calls;
        return v1::CalibrateResponse();
      },
      CalibrateCellOptions{}, stop);
  EXPECT_EQ(calls, 0);
  EXPECT_TRUE(absl::IsCancelled(views[0].status)) << views[0].status;
}

}  // namespace
}  // namespace surfinspect::client
