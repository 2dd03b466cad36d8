#include "core/report/grid_thinning.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

namespace surfinspect {
namespace {

// A sheet of n x n points on a regular 16-bit grid, z from a bump.
void Sheet(int n, std::vector<uint16_t>& xyz, std::vector<float>& priority) {
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int x = i * 65535 / (n - 1), y = j * 65535 / (n - 1);
      xyz.insert(xyz.end(), {static_cast<uint16_t>(x), static_cast<uint16_t>(y), 30000});
      priority.push_back(static_cast<float>((i * 7919 + j * 104729) % 1000) / 1000.0f);
    }
}

TEST(GridThinning, MortonCodeInterleavesBits) {
  EXPECT_EQ(MortonCode48(1, 0, 0), 1u);
  EXPECT_EQ(MortonCode48(0, 1, 0), 2u);
  EXPECT_EQ(MortonCode48(0, 0, 1), 4u);
  EXPECT_EQ(MortonCode48(2, 0, 0), 8u);
  EXPECT_EQ(MortonCode48(0xFFFF, 0xFFFF, 0xFFFF), (uint64_t{1} << 48) - 1);
}

TEST(GridThinning, UnderTheCapKeepsEverythingInOrder) {
  std::vector<uint16_t> xyz;
  std::vector<float> priority;
  Sheet(30, xyz, priority);
  const ThinningResult r = ThinOnGrid(xyz, priority, 900);
  EXPECT_EQ(r.level, -1);
  ASSERT_EQ(r.kept.size(), 900u);
  for (uint32_t i = 0; i < 900; ++i) EXPECT_EQ(r.kept[i], i);
}

TEST(GridThinning, KeepsAtMostTheCapAndFillsIt) {
  std::vector<uint16_t> xyz;
  std::vector<float> priority;
  Sheet(300, xyz, priority);  // 90000 points
  for (std::size_t cap : {1u, 10u, 1000u, 20000u, 44999u, 89999u}) {
    const ThinningResult r = ThinOnGrid(xyz, priority, cap);
    EXPECT_LE(r.kept.size(), cap);
    EXPECT_GE(r.level, 0);
    // Each point at most once.
    EXPECT_EQ(std::set<uint32_t>(r.kept.begin(), r.kept.end()).size(), r.kept.size());
    // k per cell is the largest that fits and k + 1 would not, so at least
    // k / (k + 1) >= half of the budget is used.
    EXPECT_GE(2 * r.kept.size(), cap) << cap;
    EXPECT_LE(r.cells, cap);
  }
}

TEST(GridThinning, EachCellKeepsItsLargestPriority) {
  // 8 points share every coarse cell; the largest priority must survive.
  std::vector<uint16_t> xyz;
  std::vector<float> priority;
  std::mt19937 rng(3);
  for (int cell = 0; cell < 1000; ++cell)
    for (int k = 0; k < 8; ++k) {
      const uint16_t base = static_cast<uint16_t>(cell * 64);
      xyz.insert(xyz.end(), {static_cast<uint16_t>(base + k), base, 0});
      priority.push_back(std::uniform_real_distribution<float>(0, 1)(rng));
    }
  const ThinningResult r = ThinOnGrid(xyz, priority, 1000);
  ASSERT_EQ(r.kept.size(), 1000u);
  for (int cell = 0; cell < 1000; ++cell) {
    const auto first = priority.begin() + cell * 8;
    const uint32_t best =
        static_cast<uint32_t>(std::max_element(first, first + 8) - priority.begin());
    EXPECT_NE(std::find(r.kept.begin(), r.kept.end(), best), r.kept.end()) << "cell " << cell;
  }
}

TEST(GridThinning, Deterministic) {
  std::vector<uint16_t> xyz;
  std::vector<float> priority;
  Sheet(200, xyz, priority);
  EXPECT_EQ(ThinOnGrid(xyz, priority, 5000).kept, ThinOnGrid(xyz, priority, 5000).kept);
}

}  // namespace
}  // namespace surfinspect
