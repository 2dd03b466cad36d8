#include "core/plan/surface_neighbourhood.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

namespace surfinspect {
namespace {

// An error map whose closest points are the points themselves; every 13th
// point unmatched.
ErrorMapResult MapOf(const PointCloud& cloud, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> g(0, 0.05f);
  ErrorMapResult em;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const bool matched = i % 13 != 5 && PointCloud::IsValid(cloud.points[i]);
    em.deviation_mm.push_back(matched ? g(rng) : NAN);
    em.triangle_id.push_back(matched ? 0 : UINT32_MAX);
    em.closest_point.push_back(cloud.points[i]);
  }
  return em;
}

std::set<uint32_t> BruteForce(const ErrorMapResult& em, const PointCloud& cloud, std::size_t i,
                              float reach) {
  std::set<uint32_t> out;
  for (std::size_t j = 0; j < cloud.size(); ++j)
    if (em.triangle_id[j] != UINT32_MAX && (cloud.points[i] - cloud.points[j]).norm() <= reach)
      out.insert(static_cast<uint32_t>(j));
  return out;
}

std::set<uint32_t> AsSet(const std::vector<uint32_t>& v) { return {v.begin(), v.end()}; }

// Every point with `need` same-sign hot points among its neighbours must be flagged.
void ExpectMayExceedIsASuperset(const SurfaceNeighbourhood& nb, const ErrorMapResult& em,
                                bool expect_skips) {
  std::vector<int8_t> hot(em.deviation_mm.size());
  for (std::size_t i = 0; i < hot.size(); ++i)
    hot[i] = em.deviation_mm[i] > 0.04f ? 1 : em.deviation_mm[i] < -0.04f ? -1 : 0;
  const uint32_t need = 4;
  const std::vector<uint8_t> may = nb.MayExceed(hot, need);
  std::vector<uint32_t> near;
  std::size_t flagged = 0, required = 0;
  for (uint32_t i : nb.MatchedOrder()) {
    nb.Local(i, near);
    uint32_t pos = 0, neg = 0;
    for (uint32_t j : near) pos += hot[j] > 0, neg += hot[j] < 0;
    if (pos >= need || neg >= need) {
      ++required;
      EXPECT_TRUE(may[i]) << "point " << i;
    }
    flagged += may[i];
  }
  EXPECT_GT(required, 0u);
  if (expect_skips) {
    EXPECT_LT(flagged, nb.MatchedOrder().size()) << "the screen skips points";
  }
}

TEST(SurfaceNeighbourhood, CellGridEqualsBruteForce) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<float> u(0, 10), h(0, 0.3f);
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i < 4000; ++i) pts.emplace_back(u(rng), u(rng), h(rng));
  const PointCloud cloud = PointCloud::Unorganized(pts);
  const ErrorMapResult em = MapOf(cloud, 4);
  const auto nb = MakeCellNeighbourhood(em, cloud, 0.5f, 0.3f);
  std::vector<uint32_t> order = nb->MatchedOrder(), near;
  std::vector<uint32_t> matched;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (em.triangle_id[i] != UINT32_MAX) matched.push_back(static_cast<uint32_t>(i));
  std::sort(order.begin(), order.end());
  EXPECT_EQ(order, matched) << "a permutation of the matched points";
  for (std::size_t i = 0; i < cloud.size(); i += 7) {
    if (em.triangle_id[i] == UINT32_MAX) continue;
    nb->Local(i, near);
    const std::set<uint32_t> want = BruteForce(em, cloud, i, 0.5f);
    EXPECT_EQ(AsSet(near), want) << "point " << i;
    EXPECT_EQ(near.size(), want.size()) << "no duplicates";
    EXPECT_DOUBLE_EQ(nb->Area(i), M_PI * 0.25 / want.size());
    nb->Links(i, near);
    EXPECT_EQ(AsSet(near), BruteForce(em, cloud, i, 0.3f)) << "point " << i;
  }
  ExpectMayExceedIsASuperset(*nb, em, false);  // 27 cells of ~10 points: all flagged
}

// A flat 60 x 50 grid at 0.25 mm pitch with a few NaN pixels.
PointCloud FlatGrid() {
  PointCloud cloud = PointCloud::Organized(60, 50);
  std::mt19937_64 rng(9);
  std::normal_distribution<float> g(0, 0.01f);
  for (uint32_t r = 0; r < 50; ++r)
    for (uint32_t c = 0; c < 60; ++c)
      cloud.points[r * 60 + c] = (r * 60 + c) % 31 == 0
                                     ? Eigen::Vector3f::Constant(NAN)
                                     : Eigen::Vector3f(0.25f * c, 0.25f * r, g(rng));
  return cloud;
}

TEST(SurfaceNeighbourhood, GridWindowEqualsBruteForce) {
  const PointCloud cloud = FlatGrid();
  const ErrorMapResult em = MapOf(cloud, 5);
  // Radius 0.625 mm = 2.5 pitches: the 7 x 7 window holds every point within it.
  const auto nb = MakeGridNeighbourhood(em, cloud, 0.625f, 0.4f, 0.25);
  std::vector<uint32_t> near;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (em.triangle_id[i] == UINT32_MAX) continue;
    nb->Local(i, near);
    EXPECT_EQ(AsSet(near), BruteForce(em, cloud, i, 0.625f)) << "pixel " << i;
    nb->Links(i, near);
    // 0.4 mm reaches the 8-neighbours (0.25 and 0.354 mm) and nothing farther.
    EXPECT_EQ(AsSet(near), BruteForce(em, cloud, i, 0.4f)) << "pixel " << i;
  }
  // Interior pixel with all four neighbours: the footprint is the pitch squared.
  EXPECT_NEAR(nb->Area(20 * 60 + 20), 0.0625, 1e-4);
  ExpectMayExceedIsASuperset(*nb, em, true);
}

TEST(SurfaceNeighbourhood, SpacingOfGridsAndUnorganizedClouds) {
  const PointCloud grid = FlatGrid();
  const ErrorMapResult em = MapOf(grid, 6);
  EXPECT_NEAR(EstimateSurfaceSpacing(em, grid), 0.25, 0.002);
  // The same points unorganized: the area per point gives the same spacing
  // (edge points see half a disc, the median does not).
  std::vector<Eigen::Vector3f> pts;
  ErrorMapResult em2;
  for (std::size_t i = 0; i < grid.size(); ++i)
    if (em.triangle_id[i] != UINT32_MAX) {
      pts.push_back(grid.points[i]);
      em2.deviation_mm.push_back(0);
      em2.triangle_id.push_back(0);
      em2.closest_point.push_back(grid.points[i]);
    }
  const double unorganized = EstimateSurfaceSpacing(em2, PointCloud::Unorganized(pts));
  EXPECT_NEAR(unorganized, 0.25 * std::sqrt(31.0 / 30 * 13.0 / 12), 0.02);
}

}  // namespace
}  // namespace surfinspect
