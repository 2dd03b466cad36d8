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

// V::kWidth link tests at once (V::kWidth divides 64): lane bits of the
// pixels whose distance to their neighbour at (bx, by, bz) is within the
// link distance; NaN never links.
template <class V>
inline uint64_t LinkBits(typename V::Vec px, typename V::Vec py, typename V::Vec pz,
                         const float* bx, const float* by, const float* bz, typename V::Vec r2) {
  const auto dx = V::Sub(px, V::Load(bx)), dy = V::Sub(py, V::Load(by)),
             dz = V::Sub(pz, V::Load(bz));
  return V::LessEqual(V::Add(V::Add(V::Mul(dx, dx), V::Mul(dy, dy)), V::Mul(dz, dz)), r2);
}

template <class V, bool kAbove, bool kDiagonals>
bool PassOf(const float* const cur[3], const float* const up[3], uint32_t words, float r2,
            uint64_t* const masks[5]) {
  constexpr uint64_t kAllLanes = (uint64_t{1} << V::kWidth) - 1;
  const float *x = cur[0], *y = cur[1], *z = cur[2];
  const float *ux = up[0], *uy = up[1], *uz = up[2];
  const auto r = V::Set1(r2);
  uint64_t any_inf = 0;
  for (uint32_t k = 0; k < words; ++k) {
    uint64_t valid = 0, west = 0, north_west = 0, north = 0, north_east = 0;
    for (uint32_t j = 0; j < 64; j += V::kWidth) {
      const uint32_t i = 64 * k + j;
      const auto px = V::Load(x + i), py = V::Load(y + i), pz = V::Load(z + i);
      const uint64_t bad = V::NotFinite(px, py, pz);
      if (bad != 0) {
        any_inf |= V::Infinite(px, py, pz);
        // A pixel without data links to nothing: a block of them (a
        // shadow, the background) skips the link tests, the pass's float work.
        if (bad == kAllLanes) continue;
      }
      valid |= (~bad & kAllLanes) << j;
      west |= LinkBits<V>(px, py, pz, x + i - 1, y + i - 1, z + i - 1, r) << j;
      if (kAbove) north |= LinkBits<V>(px, py, pz, ux + i, uy + i, uz + i, r) << j;
      if (kDiagonals) {
        north_west |= LinkBits<V>(px, py, pz, ux + i - 1, uy + i - 1, uz + i - 1, r) << j;
        north_east |= LinkBits<V>(px, py, pz, ux + i + 1, uy + i + 1, uz + i + 1, r) << j;
      }
    }
    masks[0][k] = valid, masks[1][k] = west;
    masks[2][k] = north_west, masks[3][k] = north, masks[4][k] = north_east;
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

}  // namespace
}  // namespace surfinspect::link_row
