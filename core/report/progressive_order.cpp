#include "core/report/progressive_order.h"

#include "core/report/grid_thinning.h"
#include "core/types/radix_sort.h"

namespace surfinspect {

uint32_t ReverseBits(uint32_t r, int bits) {
  r = ((r >> 1) & 0x55555555u) | ((r & 0x55555555u) << 1);
  r = ((r >> 2) & 0x33333333u) | ((r & 0x33333333u) << 2);
  r = ((r >> 4) & 0x0F0F0F0Fu) | ((r & 0x0F0F0F0Fu) << 4);
  r = ((r >> 8) & 0x00FF00FFu) | ((r & 0x00FF00FFu) << 8);
  r = (r >> 16) | (r << 16);
  return bits == 0 ? 0 : r >> (32 - bits);
}

std::vector<uint32_t> ProgressiveOrder(const std::vector<uint16_t>& xyz,
                                       const std::vector<uint32_t>& points) {
  const std::size_t n = points.size();
  std::vector<uint64_t> codes(n);
  std::vector<uint32_t> sorted = points;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t p = 3 * std::size_t{points[i]};
    codes[i] = MortonCode48(xyz[p], xyz[p + 1], xyz[p + 2]);
  }
  RadixSortPairs(codes, sorted, 48);
  int bits = 0;
  while ((std::size_t{1} << bits) < n) ++bits;
  std::vector<uint32_t> out;
  out.reserve(n);
  for (std::size_t r = 0; r < (std::size_t{1} << bits); ++r) {
    const uint32_t rank = ReverseBits(static_cast<uint32_t>(r), bits);
    if (rank < n) out.push_back(sorted[rank]);
  }
  return out;
}

}  // namespace surfinspect
