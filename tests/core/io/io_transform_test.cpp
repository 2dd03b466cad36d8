#include "core/io/io_transform.h"

#include <gtest/gtest.h>

#include "core/types/transform.h"
#include "tests/support/temp_dir.h"

namespace surfinspect {
namespace {

TEST(IoTransform, RoundTripIsExact) {
  testing::TempDir dir;
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  t.translation() = Eigen::Vector3d(12.5, -400.25, 1e-3);
  ASSERT_TRUE(WriteTransformJson(dir.File("t.json"), t).ok());
  auto back = ReadTransformJson(dir.File("t.json"));
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_LT((back->matrix() - t.matrix()).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(IoTransform, RejectsMalformed) {
  const char* bad[] = {
      "not json",
      "{\"matrix\": [[1,0,0],[0,1,0],[0,0,1]]}",
      "{\"matrix\": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,2]]}",
      "{\"matrix\": [[2,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}",   // scaled
      "{\"matrix\": [[-1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}",  // reflection
      "{\"matrix\": [[1,0,0,\"a\"],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}",
      "{\"matrix\": [[1,0,0,1e999],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}",  // inf
      "{\"rotation\": 1}",
  };
  for (const char* text : bad) EXPECT_FALSE(ParseTransformJson(text, "t.json").ok()) << text;
}

TEST(Transform, ComposeReadsLeftToRight) {
  Eigen::Isometry3d world_from_gauge = Eigen::Isometry3d::Identity();
  world_from_gauge.translation() = Eigen::Vector3d(100, 0, 0);
  Eigen::Isometry3d gauge_from_sensor = Eigen::Isometry3d::Identity();
  gauge_from_sensor.linear() =
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d p_sensor(1, 0, 0);
  const Eigen::Vector3d p_world = world_from_gauge * gauge_from_sensor * p_sensor;
  EXPECT_TRUE(p_world.isApprox(Eigen::Vector3d(100, 1, 0)));
  const PoseDifference d = ComparePoses(world_from_gauge, world_from_gauge * gauge_from_sensor);
  EXPECT_NEAR(d.rotation_deg, 90.0, 1e-9);
  EXPECT_NEAR(d.translation_mm, 0.0, 1e-12);
}

TEST(PointCloud, ValidationAndTransformKeepGrid) {
  PointCloud c = PointCloud::Organized(3, 2);
  c.points[1] = {1, 2, 3};
  EXPECT_TRUE(c.Validate().ok());
  EXPECT_EQ(c.CountValid(), 1u);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(0, 0, 10);
  const PointCloud moved = TransformCloud(c, t);
  EXPECT_EQ(moved.width, 3u);
  EXPECT_EQ(moved.points[1], Eigen::Vector3f(1, 2, 13));
  EXPECT_FALSE(PointCloud::IsValid(moved.points[0]));
  c.points[2] = {1, INFINITY, 3};
  EXPECT_FALSE(c.Validate().ok());
  c.points.pop_back();
  EXPECT_FALSE(c.Validate().ok());
}

}  // namespace
}  // namespace surfinspect
