#include "core/types/float_scan.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <cstring>

namespace surfinspect {
namespace {

// Below this many floats one pass costs less than handing out tasks.
constexpr std::size_t kParallelFloats = std::size_t{3} << 18;
constexpr std::size_t kBlockFloats = std::size_t{3} << 16;

bool AnyIn(const float* f, std::size_t n, uint32_t mask, uint32_t value) {
  uint32_t hit = 0;
  for (std::size_t i = 0; i < n; ++i) {
    uint32_t bits;
    std::memcpy(&bits, f + i, sizeof bits);
    hit |= static_cast<uint32_t>((bits & mask) == value);
  }
  return hit != 0;
}

}  // namespace

bool AnyFloatWithBits(const float* f, std::size_t n, uint32_t mask, uint32_t value) {
  if (n < kParallelFloats) return AnyIn(f, n, mask, value);
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, kBlockFloats), false,
      [&](const tbb::blocked_range<std::size_t>& block, bool found) {
        return found || AnyIn(f + block.begin(), block.size(), mask, value);
      },
      [](bool a, bool b) { return a || b; });
}

}  // namespace surfinspect
