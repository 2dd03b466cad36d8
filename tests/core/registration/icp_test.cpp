#include "core/registration/icp.h"

#include <gtest/gtest.h>

#include <random>

#include "core/simulation/demo_cell.h"
#include "core/simulation/scan_simulator.h"
#include "core/types/transform.h"

namespace surfinspect {
namespace {

class Icp : public ::testing::Test {
 protected:
  void SetUp() override {
    gauge_ = MakeGaugeMesh();
    auto index = MeshIndex::Build(gauge_);
    ASSERT_TRUE(index.ok());
    index_ = *std::move(index);
    // A noise-free scan of the gauge: every point lies on the mesh, so the
    // truth is known exactly (sensor frame == gauge frame here).
    sensor_pose_ = LookAt({20, -30, 420}, {0, 0, 10});
    auto scan = SimulateScan(gauge_, Eigen::Isometry3d::Identity(), sensor_pose_, {}, {});
    ASSERT_TRUE(scan.ok());
    scan_ = scan->cloud_in_sensor;
  }
  Eigen::Isometry3d Off(double mm, double deg) const {
    Eigen::Isometry3d d = Eigen::Isometry3d::Identity();
    d.linear() = Eigen::AngleAxisd(deg * M_PI / 180, Eigen::Vector3d(1, 2, -1).normalized())
                     .toRotationMatrix();
    d.translation() = mm * Eigen::Vector3d(-2, 1, 1).normalized();
    return sensor_pose_ * d;
  }
  TriangleMesh gauge_;
  std::unique_ptr<MeshIndex> index_;
  Eigen::Isometry3d sensor_pose_;
  PointCloud scan_;
};

TEST_F(Icp, BothStepsRecoverTheExactPose) {
  for (IcpStep step : {IcpStep::kPointToPoint, IcpStep::kPointToPlane}) {
    IcpSettings s;
    s.step = step;
    auto r = RunIcp(*index_, scan_, Off(2, 0.5), s);
    ASSERT_TRUE(r.ok()) << r.status();
    const PoseDifference e = ComparePoses(sensor_pose_, r->mesh_from_points);
    EXPECT_EQ(r->cost_history.size(), std::size_t(r->iterations) + 1);
    if (step == IcpStep::kPointToPlane) {
      EXPECT_LT(e.translation_mm, 1e-3);
      EXPECT_LT(e.rotation_deg, 1e-4);
      EXPECT_TRUE(r->converged);
      EXPECT_LT(r->rms_mm, 1e-3);
      EXPECT_LT(r->cost_history.back(), 1e-3 * r->cost_history.front());
    } else {
      // Horn's step converges linearly and slides slowly along the plate:
      // within 100 iterations it gets to tens of µm (the calibration's
      // coarse stage brings it closer before it starts).
      EXPECT_LT(e.translation_mm, 0.1);
      EXPECT_LT(e.rotation_deg, 0.05);
      EXPECT_LT(r->cost_history.back(), 0.1 * r->cost_history.front());
    }
  }
}

TEST_F(Icp, SameResultWithOneAndManyThreads) {
  IcpSettings s;
  s.threads = 1;
  auto a = RunIcp(*index_, scan_, Off(2, 0.5), s);
  s.threads = 2;
  auto b = RunIcp(*index_, scan_, Off(2, 0.5), s);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->mesh_from_points.matrix(), b->mesh_from_points.matrix());
  EXPECT_EQ(a->cost_history, b->cost_history);
}

TEST_F(Icp, TukeyKernelAndTrimmingResistGrossOutliers) {
  PointCloud noisy = scan_;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-4.f, 4.f);
  std::size_t k = 0;
  for (auto& p : noisy.points)
    if (PointCloud::IsValid(p) && (k++ % 20 == 0)) p += Eigen::Vector3f(u(rng), u(rng), u(rng));
  IcpSettings s;
  s.step = IcpStep::kPointToPlane;
  s.kernel = RobustKernel::kTukey;
  s.kernel_scale_mm = 1.0;
  s.trim_fraction = 0.1;
  auto r = RunIcp(*index_, noisy, Off(1, 0.3), s);
  ASSERT_TRUE(r.ok()) << r.status();
  const PoseDifference e = ComparePoses(sensor_pose_, r->mesh_from_points);
  EXPECT_LT(e.translation_mm, 0.01);
  EXPECT_LT(e.rotation_deg, 0.002);
}

TEST_F(Icp, StopReasons) {
  IcpSettings s;
  s.max_iterations = 2;
  auto r = RunIcp(*index_, scan_, Off(5, 5), s);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->stop_reason, IcpStopReason::kMaxIterations);
  EXPECT_FALSE(r->converged);
  EXPECT_EQ(r->iterations, 2);
  s.max_iterations = 100;
  s.absolute_cost_mm2 = 1e9;
  r = RunIcp(*index_, scan_, Off(5, 5), s);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->stop_reason, IcpStopReason::kAbsoluteCost);
  EXPECT_EQ(r->iterations, 0);
  EXPECT_STREQ(ToString(IcpStopReason::kRelativeChange), "relative_change");
}

TEST_F(Icp, RejectsBadInput) {
  IcpSettings s;
  s.trim_fraction = 0.95;
  EXPECT_EQ(RunIcp(*index_, scan_, Off(1, 1), s).status().code(),
            absl::StatusCode::kInvalidArgument);
  s = {};
  s.min_correspondence_mm = NAN;
  EXPECT_EQ(RunIcp(*index_, scan_, Off(1, 1), s).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(RunIcp(*index_, PointCloud::Organized(4, 4), Off(1, 1), {}).status().code(),
            absl::StatusCode::kInvalidArgument);
  Eigen::Isometry3d nan_pose = Off(1, 1);
  nan_pose.translation().x() = NAN;
  EXPECT_EQ(RunIcp(*index_, scan_, nan_pose, {}).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace surfinspect
