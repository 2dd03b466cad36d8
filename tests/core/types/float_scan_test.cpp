#include "core/types/float_scan.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

namespace surfinspect {
namespace {

// A single matching float anywhere (either end, the middle, every 4097th
// place) is found, with the mask applied; an array without one is not.
TEST(FloatScan, FindsOneMatchingFloatAnywhere) {
  for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{7}, std::size_t{100003}}) {
    std::vector<float> v(n, 1.5f);
    EXPECT_FALSE(AnyFloatWithBits(v.data(), n, 0x7fffffffu, 0x7f800000u)) << n;
    EXPECT_FALSE(AnyFloatWithBits(v.data(), n, 0xffffffffu, 0x80000000u)) << n;
    EXPECT_EQ(AnyFloatWithBits(v.data(), n, 0xffffffffu, 0x3fc00000u), n > 0) << "1.5f";
    std::vector<std::size_t> where = {0, n / 2, n - 1};
    for (std::size_t at = 4097; at < n; at += 4097) where.push_back(at);
    for (std::size_t at : where) {
      if (at >= n) continue;
      for (float odd : {-0.0f, INFINITY, -INFINITY, 0.0f}) {
        v[at] = odd;
        EXPECT_EQ(AnyFloatWithBits(v.data(), n, 0xffffffffu, 0x80000000u),
                  std::signbit(odd) && odd == 0)
            << n << " " << at;
        EXPECT_EQ(AnyFloatWithBits(v.data(), n, 0x7fffffffu, 0x7f800000u), std::isinf(odd))
            << n << " " << at;
        v[at] = 1.5f;
      }
    }
  }
}

}  // namespace
}  // namespace surfinspect
