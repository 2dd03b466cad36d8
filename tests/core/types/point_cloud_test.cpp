#include "core/types/point_cloud.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "absl/strings/str_cat.h"

namespace surfinspect {
namespace {

using Eigen::Vector3f;

TEST(PointCloud, OrganizedIsAllNoDataAndUnorganizedIsOneRow) {
  const PointCloud grid = PointCloud::Organized(7, 5);
  EXPECT_EQ(grid.width, 7u);
  EXPECT_EQ(grid.height, 5u);
  ASSERT_EQ(grid.size(), 35u);
  EXPECT_TRUE(grid.organized());
  EXPECT_EQ(grid.CountValid(), 0u);
  for (const auto& p : grid.points) EXPECT_TRUE(p.array().isNaN().all());
  EXPECT_TRUE(grid.Validate().ok());

  EXPECT_FALSE(PointCloud::Organized(9, 1).organized()) << "one row is a plain list";
  EXPECT_TRUE(PointCloud::Organized(0, 0).empty());

  const PointCloud list = PointCloud::Unorganized({{1, 2, 3}, {4, 5, 6}, {7, 8, 9}});
  EXPECT_EQ(list.width, 3u);
  EXPECT_EQ(list.height, 1u);
  EXPECT_FALSE(list.organized());
  EXPECT_EQ(list.points[1], Vector3f(4, 5, 6));
  EXPECT_TRUE(list.Validate().ok());
}

TEST(PointCloud, IsValidNeedsThreeFiniteCoordinates) {
  EXPECT_TRUE(PointCloud::IsValid({0, -1e30f, 1e30f}));
  for (int k = 0; k < 3; ++k)
    for (float bad : {NAN, INFINITY, -INFINITY}) {
      Vector3f p(1, 2, 3);
      p[k] = bad;
      EXPECT_FALSE(PointCloud::IsValid(p)) << "coordinate " << k << " = " << bad;
    }
}

TEST(PointCloud, CountValidAndForEachValidVisitTheValidPixelsInStorageOrder) {
  // A 6 x 4 grid with a known pattern of holes: pixel (row, col) holds
  // (col, row, row * 6 + col) where (row + 2 col) % 3 != 0, NaN elsewhere.
  PointCloud grid = PointCloud::Organized(6, 4);
  std::vector<std::size_t> expected;
  for (uint32_t row = 0; row < 4; ++row)
    for (uint32_t col = 0; col < 6; ++col) {
      if ((row + 2 * col) % 3 == 0) continue;
      const std::size_t i = row * 6 + col;
      grid.points[i] = Vector3f(col, row, static_cast<float>(i));
      expected.push_back(i);
    }
  EXPECT_EQ(grid.CountValid(), expected.size());
  std::vector<std::size_t> visited;
  grid.ForEachValid([&](std::size_t i, const Vector3f& p) {
    visited.push_back(i);
    // index = row * width + col
    EXPECT_EQ(p, Vector3f(i % 6, i / 6, static_cast<float>(i)));
  });
  EXPECT_EQ(visited, expected);
}

TEST(PointCloud, CountValidMatchesABruteCountOnRandomHoles) {
  // Any coordinate, or several, NaN (of either sign), +-inf, or a finite
  // extreme (the largest float, the smallest subnormal, -0): counted as
  // IsValid counts them.
  std::mt19937 rng(5);
  const float values[] = {1.5f,
                          NAN,
                          -NAN,
                          INFINITY,
                          -INFINITY,
                          std::numeric_limits<float>::max(),
                          -std::numeric_limits<float>::max(),
                          std::numeric_limits<float>::denorm_min(),
                          -0.0f};
  std::uniform_int_distribution<int> pick(0, std::size(values) - 1);
  std::bernoulli_distribution odd(0.3);
  std::vector<Vector3f> pts(5000);
  std::size_t valid = 0;
  for (auto& p : pts) {
    p = Vector3f(1, 2, 3);
    for (int k = 0; k < 3; ++k)
      if (odd(rng)) p[k] = values[pick(rng)];
    const bool finite = std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z());
    valid += finite ? 1 : 0;
  }
  EXPECT_GT(valid, 1000u);
  EXPECT_LT(valid, 4000u);
  EXPECT_EQ(PointCloud::Unorganized(pts).CountValid(), valid);
}

TEST(PointCloud, ValidateChecksTheGridAndRejectsInfinities) {
  PointCloud c = PointCloud::Organized(4, 3);
  c.points[5] = Vector3f(1, 2, 3);
  EXPECT_TRUE(c.Validate().ok()) << "NaN pixels are no data, not an error";

  PointCloud wrong = c;
  wrong.width = 5;
  const absl::Status size = wrong.Validate();
  EXPECT_EQ(size.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(size.message().find("5*3"), std::string::npos) << size;
  EXPECT_NE(size.message().find("12 points"), std::string::npos) << size;

  for (const Vector3f& bad : {Vector3f(1, INFINITY, 2), Vector3f(NAN, -INFINITY, NAN)}) {
    PointCloud inf = c;
    inf.points[7] = bad;
    const absl::Status st = inf.Validate();
    EXPECT_EQ(st.code(), absl::StatusCode::kInvalidArgument);
    EXPECT_NE(st.message().find("point 7"), std::string::npos) << st;
    EXPECT_NE(st.message().find("infinite"), std::string::npos) << st;
  }
}

// The check reads the floats as one array: an infinity anywhere, on any
// axis and of either sign, among NaNs and finite points, is found and named
// by its point; a cloud of NaNs, huge and tiny finite values passes.
TEST(PointCloud, ValidateFindsEveryInfinityAndNamesTheFirst) {
  PointCloud c = PointCloud::Unorganized(std::vector<Vector3f>(37, Vector3f(1, -2, 3)));
  c.points[3] = Vector3f(NAN, NAN, NAN);
  c.points[4] = Vector3f(3.4e38f, -3.4e38f, 1e-45f);
  c.points[5] = Vector3f(NAN, 0, -0.f);
  ASSERT_TRUE(c.Validate().ok());
  for (std::size_t i = 0; i < c.size(); ++i)
    for (int axis = 0; axis < 3; ++axis)
      for (float inf : {INFINITY, -INFINITY}) {
        PointCloud bad = c;
        bad.points[i][axis] = inf;
        if (i + 7 < c.size()) bad.points[i + 7][2] = INFINITY;  // a later one is not named
        const absl::Status st = bad.Validate();
        ASSERT_EQ(st.code(), absl::StatusCode::kInvalidArgument) << i << " " << axis;
        EXPECT_NE(st.message().find(absl::StrCat("point ", i, " has")), std::string::npos) << st;
      }
}

TEST(PointCloud, ValidatePointsLooksOnlyAtItsRange) {
  PointCloud c = PointCloud::Unorganized(std::vector<Vector3f>(10, Vector3f(0, 0, 0)));
  c.points[6] = Vector3f(0, 0, -INFINITY);
  EXPECT_TRUE(c.ValidatePoints(0, 6).ok());
  EXPECT_TRUE(c.ValidatePoints(7, 10).ok());
  EXPECT_TRUE(c.ValidatePoints(6, 6).ok()) << "an empty range";
  EXPECT_EQ(c.ValidatePoints(6, 7).code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(c.ValidatePoints(0, 10).code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(c.Validate().code(), absl::StatusCode::kInvalidArgument);
}

TEST(PointCloud, BoundsCoverTheValidPointsOnly) {
  PointCloud c = PointCloud::Organized(3, 2);
  EXPECT_TRUE(ComputeBounds(c).empty());
  c.points[0] = Vector3f(1, -2, 3);
  c.points[4] = Vector3f(-4, 5, 0.5f);
  c.points[5] = Vector3f(2, NAN, 100);  // invalid: must not widen the box
  const Bounds3 b = ComputeBounds(c);
  ASSERT_FALSE(b.empty());
  EXPECT_EQ(b.min, Eigen::Vector3d(-4, -2, 0.5));
  EXPECT_EQ(b.max, Eigen::Vector3d(1, 5, 3));
}

}  // namespace
}  // namespace surfinspect
