#include "core/types/float_scan.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>
#include <vector>

namespace surfinspect {
namespace {

// The answer of a plain loop over every float, the oracle.
bool Brute(const std::vector<float>& v, uint32_t mask, uint32_t value) {
  for (float f : v) {
    uint32_t bits;
    std::memcpy(&bits, &f, sizeof bits);
    if ((bits & mask) == value) return true;
  }
  return false;
}

// Small arrays take one pass, large ones are split into blocks: a single
// matching float anywhere (the ends, around each block edge) is found on
// 1 and 2 threads, and an array without one is not.
TEST(FloatScan, FindsOneMatchingFloatAnywhereInSmallAndLargeArrays) {
  for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{1000},
                        (std::size_t{3} << 18) - 1, std::size_t{3} << 18, std::size_t{3000001}}) {
    std::vector<float> v(n, 1.5f);
    for (int threads : {1, 2}) {
      tbb::task_arena arena(threads);
      arena.execute([&] {
        EXPECT_FALSE(AnyFloatWithBits(v.data(), n, 0x7fffffffu, 0x7f800000u)) << n;
        EXPECT_EQ(AnyFloatWithBits(v.data(), n, 0xffffffffu, 0x3fc00000u), n > 0) << "1.5f";
      });
    }
    std::vector<std::size_t> where = {0, n / 2};
    for (std::size_t edge = std::size_t{3} << 16; edge < n; edge += std::size_t{3} << 16)
      for (std::size_t at : {edge - 1, edge}) where.push_back(at);
    if (n > 0) where.push_back(n - 1);
    for (std::size_t at : where) {
      if (at >= n) continue;
      for (float odd : {-0.0f, INFINITY, -INFINITY}) {
        v[at] = odd;
        tbb::task_arena arena(2);
        arena.execute([&] {
          EXPECT_EQ(AnyFloatWithBits(v.data(), n, 0xffffffffu, 0x80000000u),
                    Brute(v, 0xffffffffu, 0x80000000u))
              << n << " " << at;
          EXPECT_EQ(AnyFloatWithBits(v.data(), n, 0x7fffffffu, 0x7f800000u), std::isinf(odd))
              << n << " " << at;
        });
        v[at] = 1.5f;
      }
    }
  }
}

}  // namespace
}  // namespace surfinspect
