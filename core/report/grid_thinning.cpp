#include "core/report/grid_thinning.h"

#include <algorithm>
#include <numeric>

#include "core/types/radix_sort.h"

namespace surfinspect {
namespace {

uint64_t Spread16(uint64_t v) {  // bit i -> bit 3i
  v &= 0xFFFF;
  v = (v | (v << 16)) & 0x0000FF0000FFull;
  v = (v | (v << 8)) & 0x00F00F00F00Full;
  v = (v | (v << 4)) & 0x0C30C30C30C3ull;
  v = (v | (v << 2)) & 0x249249249249ull;
  return v;
}

// Occupied cells of the 2^level grid: runs of equal code >> 3 level.
std::size_t CountCells(const std::vector<uint64_t>& sorted, int level) {
  std::size_t cells = 0;
  uint64_t prev = ~uint64_t{0};
  for (uint64_t c : sorted) {
    const uint64_t key = c >> (3 * level);
    cells += key != prev;
    prev = key;
  }
  return cells;
}

struct Child {
  uint32_t point;
  float priority;
};

// The children of each cell of `level` (cells of level - 1, or single points
// at level 0), each represented by its highest-priority point; `first[c]`
// is where cell c's children start in the returned list.
std::vector<Child> Children(const std::vector<uint64_t>& codes, const std::vector<uint32_t>& order,
                            const std::vector<float>& priority, int level,
                            std::vector<std::size_t>& first) {
  std::vector<Child> children;
  uint64_t prev_cell = ~uint64_t{0}, prev_child = ~uint64_t{0};
  for (std::size_t i = 0; i < codes.size(); ++i) {
    const uint64_t cell = codes[i] >> (3 * level);
    const uint64_t child = level == 0 ? i : codes[i] >> (3 * (level - 1));
    const Child here{order[i], priority[order[i]]};
    if (cell != prev_cell) first.push_back(children.size());
    if (cell != prev_cell || child != prev_child) {
      children.push_back(here);
    } else if (here.priority > children.back().priority) {
      children.back() = here;
    }
    prev_cell = cell;
    prev_child = child;
  }
  first.push_back(children.size());
  return children;
}

std::size_t KeptWith(const std::vector<std::size_t>& first, std::size_t k) {
  std::size_t n = 0;
  for (std::size_t c = 0; c + 1 < first.size(); ++c) n += std::min(k, first[c + 1] - first[c]);
  return n;
}

}  // namespace

uint64_t MortonCode48(uint16_t x, uint16_t y, uint16_t z) {
  return Spread16(x) | (Spread16(y) << 1) | (Spread16(z) << 2);
}

ThinningResult ThinOnGrid(const std::vector<uint16_t>& xyz, const std::vector<float>& priority,
                          std::size_t max_points) {
  ThinningResult r;
  const std::size_t n = priority.size();
  if (n <= max_points) {
    r.kept.resize(n);
    std::iota(r.kept.begin(), r.kept.end(), 0u);
    return r;
  }
  std::vector<uint64_t> codes(n);
  std::vector<uint32_t> order(n);
  for (std::size_t i = 0; i < n; ++i) {
    codes[i] = MortonCode48(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    order[i] = static_cast<uint32_t>(i);
  }
  RadixSortPairs(codes, order, 48);
  // The cell count falls as the level rises; level 16 is one cell.
  int lo = 0, hi = 16;
  while (lo < hi) {
    const int mid = (lo + hi) / 2;
    if (CountCells(codes, mid) <= max_points)
      hi = mid;
    else
      lo = mid + 1;
  }
  r.level = lo;
  std::vector<std::size_t> first;
  std::vector<Child> children = Children(codes, order, priority, r.level, first);
  r.cells = first.size() - 1;
  std::size_t largest = 0;
  for (std::size_t c = 0; c < r.cells; ++c) largest = std::max(largest, first[c + 1] - first[c]);
  std::size_t k_lo = 1, k_hi = largest;  // KeptWith(1) = cells <= max_points
  while (k_lo < k_hi) {
    const std::size_t mid = (k_lo + k_hi + 1) / 2;
    if (KeptWith(first, mid) <= max_points)
      k_lo = mid;
    else
      k_hi = mid - 1;
  }
  r.per_cell = static_cast<int>(k_lo);
  for (std::size_t c = 0; c < r.cells; ++c) {
    auto begin = children.begin() + first[c], end = children.begin() + first[c + 1];
    const std::size_t take = std::min<std::size_t>(k_lo, end - begin);
    // Stable: equal priorities keep Morton order.
    std::stable_sort(begin, end,
                     [](const Child& a, const Child& b) { return a.priority > b.priority; });
    for (auto it = begin; it != begin + take; ++it) r.kept.push_back(it->point);
  }
  return r;
}

}  // namespace surfinspect
