#include "core/types/transform.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

namespace surfinspect {
namespace {

using Eigen::Isometry3d;
using Eigen::Vector3d;

Isometry3d RandomPose(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0, 1);
  Isometry3d t = Isometry3d::Identity();
  t.linear() = Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
  t.translation() = Vector3d(n(rng), n(rng), n(rng)) * 300;
  return t;
}

TEST(Transform, RowMajorLayoutPutsTheTranslationInTheLastColumn) {
  Isometry3d t = Isometry3d::Identity();
  t.linear() = Eigen::AngleAxisd(M_PI / 2, Vector3d::UnitZ()).toRotationMatrix();
  t.translation() = Vector3d(10, 20, 30);
  const RowMajor16 m = ToRowMajor(t);
  EXPECT_DOUBLE_EQ(m[3], 10);
  EXPECT_DOUBLE_EQ(m[7], 20);
  EXPECT_DOUBLE_EQ(m[11], 30);
  // Rz(90): x -> y, so row 1 column 0 is +1 and row 0 column 1 is -1.
  EXPECT_NEAR(m[0 * 4 + 1], -1, 1e-15);
  EXPECT_NEAR(m[1 * 4 + 0], 1, 1e-15);
  EXPECT_EQ(m[12], 0);
  EXPECT_EQ(m[13], 0);
  EXPECT_EQ(m[14], 0);
  EXPECT_EQ(m[15], 1);
}

TEST(Transform, RoundTripKeepsEveryBit) {
  std::mt19937_64 rng(11);
  for (int k = 0; k < 50; ++k) {
    const Isometry3d t = RandomPose(rng);
    auto back = FromRowMajor(ToRowMajor(t), "t");
    ASSERT_TRUE(back.ok()) << back.status();
    EXPECT_EQ(back->matrix(), t.matrix()) << "pose " << k;
  }
}

TEST(Transform, FewDigitRotationsAreReorthonormalised) {
  std::mt19937_64 rng(3);
  const Isometry3d t = RandomPose(rng);
  RowMajor16 m = ToRowMajor(t);
  for (double& x : m) x = std::round(x * 1e7) / 1e7;  // printed with 7 decimals
  auto back = FromRowMajor(m, "printed");
  ASSERT_TRUE(back.ok()) << back.status();
  const Eigen::Matrix3d r = back->linear();
  EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 1e-14);
  EXPECT_NEAR(r.determinant(), 1, 1e-14);
  EXPECT_LT((r - t.linear()).norm(), 1e-6);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(back->translation()[i], m[i * 4 + 3]);
}

TEST(Transform, RejectsWhatIsNotARigidTransform) {
  const RowMajor16 identity = ToRowMajor(Isometry3d::Identity());
  auto expect_error = [](const RowMajor16& m, const std::string& needle) {
    auto r = FromRowMajor(m, "world_from_sensor");
    ASSERT_FALSE(r.ok()) << needle;
    EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_NE(r.status().message().find("world_from_sensor"), std::string::npos) << r.status();
    EXPECT_NE(r.status().message().find(needle), std::string::npos) << r.status();
  };
  RowMajor16 m = identity;
  m[1 * 4 + 2] = NAN;
  expect_error(m, "(1,2)");
  m = identity;
  m[2 * 4 + 3] = INFINITY;
  expect_error(m, "(2,3)");
  m = identity;
  m[3 * 4 + 0] = 0.5;
  expect_error(m, "last row");
  m = identity;
  m[15] = 2;
  expect_error(m, "last row");
  m = identity;
  m[0] = -1;  // a reflection: orthogonal but det = -1
  expect_error(m, "not a rotation");
  m = identity;
  for (int i : {0, 5, 10}) m[i] = 1.01;  // a scale
  expect_error(m, "not a rotation");
  m = identity;
  m[1] = 1e-3;  // a shear far beyond 1e-6
  expect_error(m, "not a rotation");
}

TEST(Transform, TransformCloudMapsValidPointsAndKeepsTheGrid) {
  std::mt19937_64 rng(7);
  const Isometry3d world_from_sensor = RandomPose(rng);
  PointCloud grid = PointCloud::Organized(5, 4);
  for (std::size_t i = 0; i < grid.size(); ++i)
    if (i % 3 != 0) grid.points[i] = Eigen::Vector3f(i, 2.0f * i, 400.0f - i);
  const PointCloud out = TransformCloud(grid, world_from_sensor);
  EXPECT_EQ(out.width, 5u);
  EXPECT_EQ(out.height, 4u);
  ASSERT_EQ(out.size(), grid.size());
  const Eigen::Matrix3d r = world_from_sensor.linear();
  const Vector3d t = world_from_sensor.translation();
  for (std::size_t i = 0; i < grid.size(); ++i) {
    if (i % 3 == 0) {
      EXPECT_TRUE(out.points[i].array().isNaN().all()) << i;
      continue;
    }
    const Vector3d expected = r * grid.points[i].cast<double>() + t;  // x' = R x + t
    EXPECT_LT((out.points[i].cast<double>() - expected).norm(), 1e-4) << i;
  }
}

// TransformKeepsCloud says true exactly when TransformCloud's output equals
// its input bit for bit: the identity on a cloud with no -0 coordinate.
TEST(Transform, TransformKeepsCloudExactlyWhenTheCopyWouldBeEqual) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<float> coord(-500.0f, 500.0f);
  PointCloud grid = PointCloud::Organized(40, 30);
  for (std::size_t i = 0; i < grid.size(); ++i)
    if (i % 7 != 0)
      grid.points[i] = Eigen::Vector3f(coord(rng), coord(rng), i % 5 ? coord(rng) : 0);
  auto same_bits = [](const PointCloud& a, const PointCloud& b) {
    return a.size() == b.size() &&
           std::memcmp(a.points.data(), b.points.data(), a.size() * sizeof(a.points[0])) == 0;
  };
  const Isometry3d identity = Isometry3d::Identity();
  const Isometry3d moved = RandomPose(rng);
  EXPECT_TRUE(TransformKeepsCloud(grid, identity));
  EXPECT_TRUE(same_bits(TransformCloud(grid, identity), grid));
  // The identity as an inverse (what the CLI passes) is still the identity.
  EXPECT_TRUE(TransformKeepsCloud(grid, identity.inverse()));
  EXPECT_FALSE(TransformKeepsCloud(grid, moved));
  EXPECT_FALSE(same_bits(TransformCloud(grid, moved), grid));
  for (int axis = 0; axis < 3; ++axis) {
    PointCloud signed_zero = grid;
    signed_zero.points[3][axis] = -0.0f;
    EXPECT_FALSE(TransformKeepsCloud(signed_zero, identity)) << axis;
    EXPECT_FALSE(same_bits(TransformCloud(signed_zero, identity), signed_zero)) << axis;
  }
}

TEST(Transform, CompositionReadsLeftToRightAndTheInverseUndoes) {
  std::mt19937_64 rng(9);
  const Isometry3d world_from_gauge = RandomPose(rng);
  const Isometry3d gauge_from_sensor = RandomPose(rng);
  std::vector<Eigen::Vector3f> pts;
  std::uniform_real_distribution<float> u(-100, 100);
  for (int i = 0; i < 200; ++i) pts.emplace_back(u(rng), u(rng), u(rng));
  const PointCloud in_sensor = PointCloud::Unorganized(pts);
  const PointCloud two_steps =
      TransformCloud(TransformCloud(in_sensor, gauge_from_sensor), world_from_gauge);
  const PointCloud one_step = TransformCloud(in_sensor, world_from_gauge * gauge_from_sensor);
  const PointCloud back =
      TransformCloud(one_step, (world_from_gauge * gauge_from_sensor).inverse());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    EXPECT_LT((two_steps.points[i] - one_step.points[i]).norm(), 1e-3) << i;
    EXPECT_LT((back.points[i] - pts[i]).norm(), 1e-3) << i;
  }
}

TEST(Transform, ComparePosesMeasuresTheRelativeMotion) {
  std::mt19937_64 rng(13);
  for (int k = 0; k < 20; ++k) {
    const Isometry3d a = RandomPose(rng);
    const Vector3d axis = Vector3d::Random().normalized();
    // b = a * delta with |delta.t| = 5 mm and a 3 degree turn.
    const Isometry3d delta =
        Eigen::Translation3d(0, 3, 4) * Eigen::AngleAxisd(3 * M_PI / 180, axis);
    const Isometry3d b = a * delta;
    const PoseDifference ab = ComparePoses(a, b);
    EXPECT_NEAR(ab.translation_mm, 5, 1e-9);
    EXPECT_NEAR(ab.rotation_deg, 3, 1e-9);
    const PoseDifference ba = ComparePoses(b, a);  // the inverse motion has the same size
    EXPECT_NEAR(ba.translation_mm, 5, 1e-9);
    EXPECT_NEAR(ba.rotation_deg, 3, 1e-9);
    const PoseDifference same = ComparePoses(a, a);
    EXPECT_NEAR(same.translation_mm, 0, 1e-9);
    EXPECT_NEAR(same.rotation_deg, 0, 1e-6);
  }
}

}  // namespace
}  // namespace surfinspect
