// The first point, in index order, of each set of points with equal
// coordinates: the vertex merge of the mesh readers and the weld of the
// mesh index. An open-addressing table of indices (linear probing, at most
// half full). Equality is float ==, so -0 meets 0 (both hash as +0) and a
// point with a NaN coordinate never meets anything. The answers depend only
// on which points are equal and on the order of the calls, never on the
// hash.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <cstring>
#include <vector>

namespace surfinspect {

class FirstEqualPoint {
 public:
  // `points` must outlive the table; `expected` sizes it (more is fine).
  FirstEqualPoint(const std::vector<Eigen::Vector3f>& points, std::size_t expected)
      : points_(points) {
    std::size_t size = 16;
    while (size < 2 * expected) size *= 2;
    slots_.assign(size, kEmpty);
    mask_ = size - 1;
  }

  // The index of the first point offered so far that equals points[i], or
  // i itself, which is then remembered, when none does.
  uint32_t FindOrAdd(uint32_t i) {
    for (std::size_t s = Hash(points_[i]) & mask_;; s = (s + 1) & mask_) {
      if (slots_[s] == kEmpty) {
        slots_[s] = i;
        if (++used_ * 2 > slots_.size()) Grow();
        return i;
      }
      if (points_[slots_[s]] == points_[i]) return slots_[s];
    }
  }

 private:
  static constexpr uint32_t kEmpty = UINT32_MAX;

  static uint64_t Hash(const Eigen::Vector3f& p) {
    uint64_t h = 0x9e3779b97f4a7c15ull;
    for (int a = 0; a < 3; ++a) {
      const float f = p[a] == 0.f ? 0.f : p[a];
      uint32_t bits;
      std::memcpy(&bits, &f, 4);
      h = (h ^ bits) * 0xff51afd7ed558ccdull;  // the murmur3 finaliser's multiplier
      h ^= h >> 32;
    }
    return h;
  }

  void Grow() {
    std::vector<uint32_t> old(slots_.size() * 2, kEmpty);
    old.swap(slots_);
    mask_ = slots_.size() - 1;
    for (uint32_t i : old) {
      if (i == kEmpty) continue;
      std::size_t s = Hash(points_[i]) & mask_;
      while (slots_[s] != kEmpty) s = (s + 1) & mask_;
      slots_[s] = i;
    }
  }

  const std::vector<Eigen::Vector3f>& points_;
  std::vector<uint32_t> slots_;
  std::size_t mask_ = 0;
  std::size_t used_ = 0;
};

}  // namespace surfinspect
