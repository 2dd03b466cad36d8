// PointsByTriangle (core/plan/triangle_points.cpp) against a direct listing:
// every matched point under its triangle, ascending, across the parallel
// blocks' seams; unmatched points left out; a bad id refused.
#include "core/plan/triangle_points.h"

#include <gtest/gtest.h>

#include <random>

namespace surfinspect {
namespace {

ErrorMapResult MapOf(const std::vector<uint32_t>& ids) {
  ErrorMapResult em;
  em.triangle_id = ids;
  em.closest_point.assign(ids.size(), Eigen::Vector3f::Zero());
  em.deviation_mm.assign(ids.size(), 0.f);
  return em;
}

TEST(TrianglePoints, ListsEachTrianglesPointsAscendingAcrossBlocks) {
  std::mt19937 rng(4);
  std::uniform_int_distribution<uint32_t> tri(0, 36);  // 36: unmatched below
  std::vector<uint32_t> ids(700000);                   // > 2 blocks of 2^18
  for (auto& id : ids) id = tri(rng) == 36 ? UINT32_MAX : tri(rng) % 36;
  auto grouped = PointsByTriangle(MapOf(ids), 40);  // triangles 36..39 hold none
  ASSERT_TRUE(grouped.ok()) << grouped.status();
  ASSERT_EQ(grouped->offsets.size(), 41u);
  std::size_t listed = 0;
  for (uint32_t t = 0; t < 40; ++t) {
    std::vector<uint32_t> expect;
    for (uint32_t i = 0; i < ids.size(); ++i)
      if (ids[i] == t) expect.push_back(i);
    const std::vector<uint32_t> got(grouped->points.begin() + grouped->begin(t),
                                    grouped->points.begin() + grouped->end(t));
    EXPECT_EQ(got, expect) << "triangle " << t;
    listed += got.size();
  }
  EXPECT_EQ(listed, grouped->points.size());
  EXPECT_LT(listed, ids.size()) << "the unmatched are left out";
}

TEST(TrianglePoints, RefusesAnIdBeyondThePartAndUnequalArrays) {
  EXPECT_EQ(PointsByTriangle(MapOf({0, 5, 2}), 5).status().code(),
            absl::StatusCode::kInvalidArgument);
  ErrorMapResult em = MapOf({0, 1});
  em.deviation_mm.pop_back();
  EXPECT_EQ(PointsByTriangle(em, 5).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(PointsByTriangle(MapOf({}), 0).ok());
}

}  // namespace
}  // namespace surfinspect
