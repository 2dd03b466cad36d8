#include "core/registration/registration.h"

#include <gtest/gtest.h>

#include <atomic>

#include "core/simulation/demo_cell.h"
#include "core/types/transform.h"

namespace surfinspect {
namespace {

class Registration : public ::testing::Test {
 protected:
  void SetUp() override {
    cell_ = MakeDemoCell();
    for (int v = 0; v < 3; ++v) {
      ScanOptions opt;
      opt.seed = 10 + v;
      auto scan = SimulateScan(cell_.part, cell_.world_from_part,
                               cell_.viewpoints[v].world_from_sensor, cell_.intrinsics, opt);
      ASSERT_TRUE(scan.ok());
      views_.push_back(
          {cell_.viewpoints[v].name, scan->cloud_in_sensor, cell_.viewpoints[v].world_from_sensor});
    }
    auto index = MeshIndex::Build(cell_.part);
    ASSERT_TRUE(index.ok());
    part_ = *std::move(index);
  }
  DemoCell cell_;
  std::vector<ViewScan> views_;
  std::unique_ptr<MeshIndex> part_;
};

TEST_F(Registration, TrueCalibrationPutsEveryViewOnTheCad) {
  auto merged = RegisterToWorld(views_);
  ASSERT_TRUE(merged.ok()) << merged.status();
  std::size_t total = 0;
  for (const auto& v : views_) total += v.cloud_in_sensor.CountValid();
  ASSERT_EQ(merged->cloud_in_world.size(), total);
  ASSERT_EQ(merged->points_per_view.size(), 3u);
  BatchQuerySettings q;
  auto d = QueryClosest(*part_, merged->cloud_in_world, cell_.world_from_part.inverse(), q);
  ASSERT_TRUE(d.ok());
  double worst = 0;
  for (const auto& c : *d) worst = std::max(worst, c.distance_mm);
  EXPECT_LT(worst, 2e-4);  // float32 coordinates of ~600 mm
  // Every merged point traces back to its pixel.
  for (std::size_t i = 0; i < merged->cloud_in_world.size(); i += 997) {
    const ViewScan& v = views_[merged->view_id[i]];
    const Eigen::Vector3d back =
        v.world_from_sensor.inverse() * merged->cloud_in_world.points[i].cast<double>();
    EXPECT_LT((back - v.cloud_in_sensor.points[merged->grid_index[i]].cast<double>()).norm(), 1e-3);
  }
}

TEST_F(Registration, BestFitFindsACommonOffsetAndReportsIt) {
  Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();
  offset.linear() =
      Eigen::AngleAxisd(0.05 * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  offset.translation() = Eigen::Vector3d(0.3, -0.2, 0.4);
  std::vector<ViewScan> shifted = views_;
  for (auto& v : shifted) v.world_from_sensor = offset * v.world_from_sensor;
  auto merged = RegisterToWorld(shifted);
  ASSERT_TRUE(merged.ok());
  auto fit = BestFitToCad(*part_, cell_.world_from_part, *merged);
  ASSERT_TRUE(fit.ok()) << fit.status();
  const PoseDifference e = ComparePoses(fit->correction * offset, Eigen::Isometry3d::Identity());
  EXPECT_LT(e.translation_mm, 0.005);
  EXPECT_LT(e.rotation_deg, 0.001);
  EXPECT_GT(fit->translation_mm, 0.1);
}

TEST(RegistrationInput, RejectsBadViews) {
  EXPECT_FALSE(RegisterToWorld({}).ok());
  ViewScan v{"v1", PointCloud::Organized(2, 2), Eigen::Isometry3d::Identity()};
  v.world_from_sensor.linear() *= 2.0;  // scaled: not rigid
  EXPECT_FALSE(RegisterToWorld({v}).ok());
  ViewScan broken{"v2", PointCloud::Organized(2, 2), Eigen::Isometry3d::Identity()};
  broken.cloud_in_sensor.points.pop_back();
  EXPECT_FALSE(RegisterToWorld({broken}).ok());
}

// Raised before the call, the flag stops it before the first view; lowered,
// the same views merge.
TEST(RegistrationInput, StopsWhenCancelled) {
  PointCloud c = PointCloud::Organized(2, 1);
  c.points = {Eigen::Vector3f(1, 2, 3), Eigen::Vector3f(4, 5, 6)};
  const std::vector<ViewScan> views = {{"v1", c, Eigen::Isometry3d::Identity()},
                                       {"v2", c, Eigen::Isometry3d::Identity()}};
  std::atomic<bool> cancel{true};
  EXPECT_EQ(RegisterToWorld(views, &cancel).status().code(), absl::StatusCode::kCancelled);
  cancel = false;
  auto merged = RegisterToWorld(views, &cancel);
  ASSERT_TRUE(merged.ok()) << merged.status();
  EXPECT_EQ(merged->cloud_in_world.size(), 4u);
}

}  // namespace
}  // namespace surfinspect
