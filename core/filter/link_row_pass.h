// The row pass of link_row_masks.h written once for any vector width, for
// the per-ISA files (link_row_masks_avx2.cpp, link_row_masks_avx512.cpp):
// `V` supplies one instruction set's loads, arithmetic and comparisons.
// Every lane computes PointsLinked's float operations in its order, so the
// masks are the same bits in each set. Include only in a file compiled for
// V's set: the functions have internal linkage, so no copy compiled with
// wider instructions can be picked by the linker for baseline code.
#pragma once

#include <cstdint>

namespace surfinspect::link_row {
namespace {

// V::kWidth link tests of the pixels (px, py, pz) against their neighbours
// (bx, by, bz): lane bits of the pixels within the link distance; NaN never
// links.
template <class V>
inline uint64_t LinkOf(typename V::Vec px, typename V::Vec py, typename V::Vec pz,
                       typename V::Vec bx, typename V::Vec by, typename V::Vec bz,
                       typename V::Vec r2) {
  const auto dx = V::Sub(px, bx), dy = V::Sub(py, by), dz = V::Sub(pz, bz);
  return V::LessEqual(V::Add(V::Add(V::Mul(dx, dx), V::Mul(dy, dy)), V::Mul(dz, dz)), r2);
}

// The same against the neighbours stored at (bx, by, bz).
template <class V>
inline uint64_t LinkBits(typename V::Vec px, typename V::Vec py, typename V::Vec pz,
                         const float* bx, const float* by, const float* bz, typename V::Vec r2) {
  return LinkOf<V>(px, py, pz, V::Load(bx), V::Load(by), V::Load(bz), r2);
}

// One 64-pixel word's masks, built V::kWidth pixels at a time.
struct WordBits {
  uint64_t valid = 0, west = 0, north_west = 0, north = 0, north_east = 0;
  void Store(uint32_t k, uint64_t* const masks[5]) const {
    masks[0][k] = valid, masks[1][k] = west;
    masks[2][k] = north_west, masks[3][k] = north, masks[4][k] = north_east;
  }
};

// The bits of the V::kWidth pixels at i (bit j of their word), given their
// coordinates and their west neighbours'; the row above is read at `up`.
// Sets any_inf's bits where a coordinate is infinite.
template <class V, bool kAbove, bool kDiagonals>
inline void GroupBits(typename V::Vec px, typename V::Vec py, typename V::Vec pz,
                      typename V::Vec wx, typename V::Vec wy, typename V::Vec wz,
                      const float* const up[3], uint32_t i, uint32_t j, typename V::Vec r,
                      WordBits& b, uint64_t& any_inf) {
  constexpr uint64_t kAllLanes = (uint64_t{1} << V::kWidth) - 1;
  const uint64_t bad = V::NotFinite(px, py, pz);
  if (bad != 0) {
    any_inf |= V::Infinite(px, py, pz);
    // A pixel without data links to nothing: a block of them (a shadow,
    // the background) skips the link tests, the pass's float work.
    if (bad == kAllLanes) return;
  }
  b.valid |= (~bad & kAllLanes) << j;
  b.west |= LinkOf<V>(px, py, pz, wx, wy, wz, r) << j;
  const float *ux = up[0], *uy = up[1], *uz = up[2];
  if (kAbove) b.north |= LinkBits<V>(px, py, pz, ux + i, uy + i, uz + i, r) << j;
  if (kDiagonals) {
    b.north_west |= LinkBits<V>(px, py, pz, ux + i - 1, uy + i - 1, uz + i - 1, r) << j;
    b.north_east |= LinkBits<V>(px, py, pz, ux + i + 1, uy + i + 1, uz + i + 1, r) << j;
  }
}

template <class V, bool kAbove, bool kDiagonals>
bool PassOf(const float* const cur[3], const float* const up[3], uint32_t words, float r2,
            uint64_t* const masks[5]) {
  const float *x = cur[0], *y = cur[1], *z = cur[2];
  const auto r = V::Set1(r2);
  uint64_t any_inf = 0;
  for (uint32_t k = 0; k < words; ++k) {
    WordBits b;
    for (uint32_t j = 0; j < 64; j += V::kWidth) {
      const uint32_t i = 64 * k + j;
      GroupBits<V, kAbove, kDiagonals>(V::Load(x + i), V::Load(y + i), V::Load(z + i),
                                       V::Load(x + i - 1), V::Load(y + i - 1), V::Load(z + i - 1),
                                       up, i, j, r, b, any_inf);
    }
    b.Store(k, masks);
  }
  return any_inf != 0;
}

// PassOf with the row's transpose in the same loop, for sets with a
// V::Transpose of V::kWidth points and a V::ShiftIn(v, before) that puts
// before's last lane ahead of v's first: the whole groups of the first
// `whole` pixels are transposed from `points` into registers (and stored to
// cur for the row below), and each pixel's west neighbour is taken from
// them, not loaded back; pixels from `whole` on are read from cur, which
// the caller has filled. The same float operations as PassOf, so the same
// bits. `ahead`, when given, is the next row's points: each group prefetches
// the same columns of it into L2, one row (12 KB for 1024 columns) ahead of
// its loads. The scan is read from L3 or memory, and the hardware
// prefetcher alone leaves the loads of the transpose stalled on one core
// (bench/link_clustering_bench.cpp shows it); prefetching the next row in
// one burst at the row's start gains nothing.
template <class V, bool kAbove, bool kDiagonals>
bool TransposedPassOf(const float* points, uint32_t whole, float* const cur[3],
                      const float* const up[3], uint32_t words, float r2, uint64_t* const masks[5],
                      const float* ahead) {
  float *x = cur[0], *y = cur[1], *z = cur[2];
  const auto r = V::Set1(r2);
  // The west neighbour of pixel 0 is the row's NaN padding.
  auto wx = V::Set1(__builtin_nanf("")), wy = wx, wz = wx;
  uint64_t any_inf = 0;
  for (uint32_t k = 0; k < words; ++k) {
    WordBits b;
    for (uint32_t j = 0; j < 64; j += V::kWidth) {
      const uint32_t i = 64 * k + j;
      typename V::Vec px, py, pz;
      if (i + V::kWidth <= whole) {
        if (ahead) {  // the same columns of the next row, which has this width
          const char* next = reinterpret_cast<const char*>(ahead + 3 * std::size_t{i});
          for (std::size_t b = 0; b < 3 * sizeof(float) * V::kWidth; b += 64)
            __builtin_prefetch(next + b, 0, 2);  // read, into L2
        }
        V::Transpose(points + 3 * std::size_t{i}, px, py, pz);
        V::Store(x + i, px), V::Store(y + i, py), V::Store(z + i, pz);
      } else {
        px = V::Load(x + i), py = V::Load(y + i), pz = V::Load(z + i);
      }
      GroupBits<V, kAbove, kDiagonals>(px, py, pz, V::ShiftIn(px, wx), V::ShiftIn(py, wy),
                                       V::ShiftIn(pz, wz), up, i, j, r, b, any_inf);
      wx = px, wy = py, wz = pz;
    }
    b.Store(k, masks);
  }
  return any_inf != 0;
}

// The pass for a row with (up) or without a row above, and with or
// without the diagonal links.
template <class V>
bool RowBitsOf(const float* const cur[3], const float* const up[3], bool diagonals, uint32_t words,
               float link_distance_sq, uint64_t* const masks[5]) {
  if (!up) return PassOf<V, false, false>(cur, cur, words, link_distance_sq, masks);
  if (diagonals) return PassOf<V, true, true>(cur, up, words, link_distance_sq, masks);
  return PassOf<V, true, false>(cur, up, words, link_distance_sq, masks);
}

// The same for TransposedPassOf.
template <class V>
bool TransposedRowBitsOf(const float* points, uint32_t whole, float* const cur[3],
                         const float* const up[3], bool diagonals, uint32_t words,
                         float link_distance_sq, uint64_t* const masks[5], const float* ahead) {
  if (!up)
    return TransposedPassOf<V, false, false>(points, whole, cur, cur, words, link_distance_sq,
                                             masks, ahead);
  if (diagonals)
    return TransposedPassOf<V, true, true>(points, whole, cur, up, words, link_distance_sq, masks,
                                           ahead);
  return TransposedPassOf<V, true, false>(points, whole, cur, up, words, link_distance_sq, masks,
                                          ahead);
}

}  // namespace
}  // namespace surfinspect::link_row
