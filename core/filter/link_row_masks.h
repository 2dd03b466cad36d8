// Row kernels of the grid link clustering (link_clustering_grid.cpp): a
// sensor row copied to structure-of-arrays, then one pass that turns it into
// 64-bit masks of valid pixels and of links to the west, north-west, north
// and north-east neighbours. With SSE2 four pixels are tested per
// instruction, with AVX2 eight, with the float operations of PointsLinked in
// its order, so the masks agree bit for bit with the scalar predicate.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace surfinspect::link_row {

// One row as structure-of-arrays, padded with NaN on both sides to a whole
// number of 64-bit mask words: a link to a pixel outside the grid compares
// NaN and is false with no bounds test. Pixel 0 of each plane sits on a
// 64-byte boundary, so a group of 16 pixels is one cache line to load or
// store, not two.
class RowSoA {
 public:
  explicit RowSoA(uint32_t padded) {
    for (int a = 0; a < 3; ++a) {
      // A vector's floats are 16-byte aligned: at most 15 floats to skip.
      buf_[a].assign(padded + 2 + 15, NAN);
      const auto first = reinterpret_cast<std::uintptr_t>(buf_[a].data() + 1);
      plane_[a] = buf_[a].data() + 1 + (64 - first % 64) % 64 / sizeof(float);
    }
  }
  RowSoA(const RowSoA&) = delete;
  RowSoA& operator=(const RowSoA&) = delete;
  float* c(int a) { return plane_[a]; }
  const float* c(int a) const { return plane_[a]; }

 private:
  std::vector<float> buf_[3];
  float* plane_[3];
};

// Per-row bit masks, bit j of word k for pixel 64k + j.
struct RowMasks {
  uint64_t *valid, *west, *north_west, *north, *north_east;
};

// The row kernels' instruction set. kAuto takes the widest the CPU has:
// AVX-512 F + DQ (16 pixels per instruction, link_row_masks_avx512.h), AVX2
// (8, link_row_masks_avx2.h) or SSE2 (4); the rows and masks are the same
// bits in each.
enum class RowIsa { kAuto, kSse2, kAvx2, kAvx512 };
bool RowIsaSupported(RowIsa isa);
// The instruction set `isa` runs as: kAuto resolved to the widest supported.
RowIsa ResolveRowIsa(RowIsa isa);

// Copies w points into the SoA row (SSE2: 4 points = 3 loads, 7 shuffles).
// `isa` must be supported.
void Transpose(const Eigen::Vector3f* pts, uint32_t w, RowSoA& row, RowIsa isa = RowIsa::kAuto);

// Fills `masks` for `words` 64-pixel words of `cur`: valid (all coordinates
// finite), west link and, when `up` (the row above) is given, north and, with
// `diagonals`, north-west and north-east links; NaN never links. Returns
// whether an infinite coordinate was seen (forbidden by the cloud contract).
// `isa` must be supported (RowIsaSupported).
bool ComputeMasks(const RowSoA& cur, const RowSoA* up, bool diagonals, uint32_t words,
                  float link_distance_sq, const RowMasks& masks, RowIsa isa = RowIsa::kAuto);

// Transpose, then ComputeMasks, with the same results; with AVX-512 in one
// pass that takes each group of 16 points from registers instead of
// storing and loading it again (bench/link_clustering_bench.cpp's grid rows
// show the gain). `next`, when given, is the next row's w points,
// prefetched where that helps. `isa` must be supported.
bool TransposeAndComputeMasks(const Eigen::Vector3f* pts, uint32_t w, RowSoA& cur, const RowSoA* up,
                              bool diagonals, uint32_t words, float link_distance_sq,
                              const RowMasks& masks, RowIsa isa = RowIsa::kAuto,
                              const Eigen::Vector3f* next = nullptr);

// Run starts (valid, not west-linked) and ends (valid, the next pixel not
// west-linked) of a row, from its valid and west masks.
void RunBounds(const RowMasks& m, uint32_t words, uint64_t* starts, uint64_t* ends);

// "No set bit" for the bit scans below.
constexpr uint32_t kNone = UINT32_MAX;
// The first set bit at index in [from, last], or kNone. It reads no word
// past last's: a run's vertical links end at the run.
inline uint32_t NextBitUpTo(const uint64_t* bits, uint32_t from, uint32_t last) {
  if (from > last) return kNone;
  uint32_t k = from / 64;
  const uint32_t k_last = last / 64;
  uint64_t w = bits[k] & (~uint64_t{0} << (from % 64));
  while (w == 0) {
    if (++k > k_last) return kNone;
    w = bits[k];
  }
  const uint32_t c = 64 * k + static_cast<uint32_t>(__builtin_ctzll(w));
  return c <= last ? c : kNone;
}

// The first set bit at index >= from in `words` mask words, or kNone.
inline uint32_t NextBit(const uint64_t* bits, uint32_t words, uint32_t from) {
  return words == 0 ? kNone : NextBitUpTo(bits, from, 64 * words - 1);
}

// Bounds of the pixels first..last of the row, which must all be valid.
// The same bits in each instruction set, the sign of a zero included.
void BoundsOfLongRun(const RowSoA& row, uint32_t first, uint32_t last, float lo[3], float hi[3],
                     RowIsa isa = RowIsa::kAuto);
inline void Bounds(const RowSoA& row, uint32_t first, uint32_t last, float lo[3], float hi[3],
                   RowIsa isa = RowIsa::kAuto) {
  if (last - first >= 8) return BoundsOfLongRun(row, first, last, lo, hi, isa);
  // Most runs of a scan are a pixel or two of an outlier: inline, scalar.
  for (int a = 0; a < 3; ++a) lo[a] = hi[a] = row.c(a)[first];
  for (uint32_t i = first + 1; i <= last; ++i)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], row.c(a)[i]);
      hi[a] = std::max(hi[a], row.c(a)[i]);
    }
}

}  // namespace surfinspect::link_row
