// The AVX-512 build of link_row_masks.cpp's transpose and row pass
// (link_row_masks_avx512.cpp, compiled with -mavx512f -mavx512dq): 16 pixels
// per instruction, the same float operations in the same order, compared
// into mask registers, so every mask bit is the SSE2 pass's. Plain types
// only, for the reason given in link_row_masks_avx2.h.
#pragma once

#include <cstdint>

namespace surfinspect::link_row::avx512 {

// As avx2::RowBits, 16 pixels at a time. Call only where AVX-512F and DQ run.
bool RowBits(const float* const cur[3], const float* const up[3], bool diagonals, uint32_t words,
             float link_distance_sq, uint64_t* const masks[5]);

// Transpose and RowBits in one pass: the pixels below `whole` (a multiple
// of 16) are read from `points` (x, y, z interleaved) and stored to cur,
// whose pixels from `whole` on the caller has filled; the same masks as
// RowBits on the transposed row. `ahead` (or null) is the next row's points,
// prefetched as the pass goes. Call only where AVX-512F and DQ run.
bool TransposedRowBits(const float* points, uint32_t whole, float* const cur[3],
                       const float* const up[3], bool diagonals, uint32_t words,
                       float link_distance_sq, uint64_t* const masks[5], const float* ahead);

// As avx2::Transpose, in whole groups of 16 points (3 loads, 6 permutes
// and 3 stores each). Call only where AVX-512F runs.
uint32_t Transpose(const float* points, uint32_t w, float* x, float* y, float* z);

// Bounds of the pixels first..last of the planes (all valid), 16 at a
// time. Returns false, leaving the caller to its 4-lane reduction, where a
// bound is zero: min and max ignore the sign of a zero, so only there can
// another lane order give another bit pattern. Call only where AVX-512F runs.
bool BoundsOfRun(const float* const row[3], uint32_t first, uint32_t last, float lo[3],
                 float hi[3]);

}  // namespace surfinspect::link_row::avx512
