#include "core/distance/morton_order.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>

#include "core/distance/morton_order_avx512.h"
#include "core/types/cancel.h"
#include "core/types/radix_sort.h"

namespace surfinspect {
namespace {

// Spreads the low 10 bits of v to every third bit (Morton interleave).
constexpr uint32_t Spread10(uint32_t v) {
  v &= 0x3ff;
  v = (v | (v << 16)) & 0x30000ff;
  v = (v | (v << 8)) & 0x300f00f;
  v = (v | (v << 4)) & 0x30c30c3;
  v = (v | (v << 2)) & 0x9249249;
  return v;
}

// Spread10 of every 10-bit value, so a code costs three loads (4 KiB, in
// the L1 cache) instead of three chains of shifts.
struct SpreadTable {
  uint32_t of[1024];
  constexpr SpreadTable() : of() {
    for (uint32_t v = 0; v < 1024; ++v) of[v] = Spread10(v);
  }
};
constexpr SpreadTable kSpread;

bool UseAvx512(MortonIsa isa) {
  return isa == MortonIsa::kAvx512 ||
         (isa == MortonIsa::kAuto && MortonIsaSupported(MortonIsa::kAvx512));
}

struct Box {
  float lo[3] = {INFINITY, INFINITY, INFINITY};
  float hi[3] = {-INFINITY, -INFINITY, -INFINITY};
};

// The bounds of the valid points, in parallel blocks. The minimum and
// maximum of the same points found in another order differ at most in the
// sign of a zero bound, which the codes below do not see: the extent and
// every difference p - min keep their values, and a zero of either sign
// falls in cell 0.
Box ParallelBounds(const PointCloud& cloud, bool avx512) {
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, cloud.size(), kCancelStride), Box{},
      [&](const tbb::blocked_range<std::size_t>& block, Box b) {
        std::size_t i = block.begin();
        if (avx512)
          i += morton::avx512::ExtendBounds(cloud.points[i].data(), block.size(), b.lo, b.hi);
        for (; i != block.end(); ++i) {
          const Eigen::Vector3f& p = cloud.points[i];
          if (!PointCloud::IsValid(p)) continue;
          for (int a = 0; a < 3; ++a)
            b.lo[a] = std::min(b.lo[a], p[a]), b.hi[a] = std::max(b.hi[a], p[a]);
        }
        return b;
      },
      [](Box a, const Box& b) {
        for (int k = 0; k < 3; ++k)
          a.lo[k] = std::min(a.lo[k], b.lo[k]), a.hi[k] = std::max(a.hi[k], b.hi[k]);
        return a;
      });
}

// items[i] = code << 32 | i for the points [begin, end).
void BlockCodes(const PointCloud& cloud, std::size_t begin, std::size_t end, const double min[3],
                double scale, bool avx512, uint64_t* items) {
  std::size_t i = begin;
  if (avx512)
    i += morton::avx512::Codes(cloud.points[i].data(), end - begin, static_cast<uint32_t>(begin),
                               min, scale, kSpread.of, items + begin);
  for (; i != end; ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    uint64_t code = uint64_t{1} << 30;
    if (PointCloud::IsValid(p)) {
      uint64_t q[3];
      for (int a = 0; a < 3; ++a)
        q[a] = static_cast<uint64_t>(std::clamp((p[a] - min[a]) * scale, 0.0, 1023.0));
      code = kSpread.of[q[0]] | (kSpread.of[q[1]] << 1) | (kSpread.of[q[2]] << 2);
    }
    items[i] = code << 32 | i;
  }
}

}  // namespace

bool MortonIsaSupported(MortonIsa isa) {
  // __builtin_cpu_supports also checks that the OS saves the registers.
  static const bool avx512 =
      __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq");
  return isa != MortonIsa::kAvx512 || avx512;
}

DefaultInitVector<uint64_t> MortonOrder(const PointCloud& cloud, const std::atomic<bool>* cancel,
                                        MortonIsa isa) {
  const bool avx512 = UseAvx512(isa);
  const Box box = ParallelBounds(cloud, avx512);
  const std::size_t n = cloud.size();
  double min[3] = {0, 0, 0}, extent = 0;
  if (box.lo[0] <= box.hi[0])
    for (int a = 0; a < 3; ++a) {
      min[a] = box.lo[a];
      extent = std::max(extent, static_cast<double>(box.hi[a]) - box.lo[a]);
    }
  const double scale = extent > 0 ? 1023.0 / extent : 0.0;
  DefaultInitVector<uint64_t> items(n);  // code << 32 | point index, written below
  std::atomic<bool> stopped{false};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kCancelStride),
                    [&](const tbb::blocked_range<std::size_t>& block) {
                      if (IsCancelled(cancel)) {
                        stopped.store(true, std::memory_order_relaxed);
                        return;
                      }
                      BlockCodes(cloud, block.begin(), block.end(), min, scale, avx512,
                                 items.data());
                    });
  if (stopped.load() || !RadixSortPacked(items, 31, cancel)) return {};
  return items;
}

}  // namespace surfinspect
