#include "core/report/progressive_order.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>

#include "core/report/grid_thinning.h"

namespace surfinspect {
namespace {

// A w x h sheet on the 16-bit grid, stored row by row (a raster scan).
std::vector<uint16_t> Sheet(int w, int h) {
  std::vector<uint16_t> xyz;
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i)
      xyz.insert(xyz.end(), {static_cast<uint16_t>(i * 65535 / (w - 1)),
                             static_cast<uint16_t>(j * 65535 / (h - 1)), 20000});
  return xyz;
}

std::vector<uint32_t> Iota(std::size_t n) {
  std::vector<uint32_t> v(n);
  std::iota(v.begin(), v.end(), 0u);
  return v;
}

// The fewest and the most points of `prefix` in any cell of a cells x cells
// grid over the sheet, relative to an even share.
std::pair<double, double> CellShare(const std::vector<uint16_t>& xyz,
                                    const std::vector<uint32_t>& prefix, int cells) {
  std::vector<int> count(cells * cells, 0);
  for (uint32_t p : prefix)
    ++count[std::min(cells - 1, xyz[3 * p] * cells / 65536) * cells +
            std::min(cells - 1, xyz[3 * p + 1] * cells / 65536)];
  const double even = static_cast<double>(prefix.size()) / (cells * cells);
  const auto [lo, hi] = std::minmax_element(count.begin(), count.end());
  return {*lo / even, *hi / even};
}

TEST(ProgressiveOrder, ReverseBitsMirrorsTheLowBits) {
  EXPECT_EQ(ReverseBits(0b0001, 4), 0b1000u);
  EXPECT_EQ(ReverseBits(0b0110, 4), 0b0110u);
  EXPECT_EQ(ReverseBits(0b1011, 4), 0b1101u);
  EXPECT_EQ(ReverseBits(1, 20), 1u << 19);
  EXPECT_EQ(ReverseBits(0x80000000u, 32), 1u);
  EXPECT_EQ(ReverseBits(5, 0), 0u);
}

TEST(ProgressiveOrder, IsAPermutationOfTheGivenPoints) {
  const std::vector<uint16_t> xyz = Sheet(37, 29);
  std::vector<uint32_t> some = Iota(37 * 29);
  std::mt19937 rng(7);
  std::shuffle(some.begin(), some.end(), rng);
  some.resize(700);
  std::vector<uint32_t> out = ProgressiveOrder(xyz, some);
  ASSERT_EQ(out.size(), some.size());
  std::sort(out.begin(), out.end());
  std::sort(some.begin(), some.end());
  EXPECT_EQ(out, some);
  EXPECT_TRUE(ProgressiveOrder(xyz, {}).empty());
  EXPECT_EQ(ProgressiveOrder(xyz, {5}), std::vector<uint32_t>{5});
}

// With n = 2^b points, the first n / 2^k are every 2^k-th point along the
// Morton curve (brute force: sort by code, take the strided ranks).
TEST(ProgressiveOrder, PowerOfTwoPrefixesAreStridesAlongTheMortonCurve) {
  const std::vector<uint16_t> xyz = Sheet(32, 32);
  std::vector<uint32_t> by_code = Iota(1024);
  auto code = [&](uint32_t p) { return MortonCode48(xyz[3 * p], xyz[3 * p + 1], xyz[3 * p + 2]); };
  std::stable_sort(by_code.begin(), by_code.end(),
                   [&](uint32_t a, uint32_t b) { return code(a) < code(b); });
  const std::vector<uint32_t> out = ProgressiveOrder(xyz, Iota(1024));
  for (int k : {10, 6, 4, 1}) {
    std::vector<uint32_t> prefix(out.begin(), out.begin() + (1024 >> k)), strided;
    for (std::size_t r = 0; r < 1024; r += std::size_t{1} << k) strided.push_back(by_code[r]);
    std::sort(prefix.begin(), prefix.end());
    std::sort(strided.begin(), strided.end());
    EXPECT_EQ(prefix, strided) << "k=" << k;
  }
}

// Any prefix covers the whole sheet evenly; the raster order's prefix of the
// same length covers only its first rows (the oracle that this can fail).
TEST(ProgressiveOrder, EveryPrefixCoversTheSheetEvenly) {
  const std::vector<uint16_t> xyz = Sheet(300, 200);  // 60,000 points, not a power of two
  const std::vector<uint32_t> out = ProgressiveOrder(xyz, Iota(60000));
  for (std::size_t length : {60000u / 16, 60000u / 5, 60000u / 2}) {
    const auto [lo, hi] = CellShare(xyz, {out.begin(), out.begin() + length}, 8);
    EXPECT_GT(lo, 0.6) << length;
    EXPECT_LT(hi, 1.4) << length;
  }
  const std::vector<uint32_t> raster = Iota(60000 / 16);
  EXPECT_EQ(CellShare(xyz, raster, 8).first, 0.0);
}

TEST(ProgressiveOrder, IsDeterministic) {
  const std::vector<uint16_t> xyz = Sheet(50, 40);
  EXPECT_EQ(ProgressiveOrder(xyz, Iota(2000)), ProgressiveOrder(xyz, Iota(2000)));
}

}  // namespace
}  // namespace surfinspect
