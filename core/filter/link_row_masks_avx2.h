// The AVX2 build of link_row_masks.cpp's transpose and row pass (link_row_masks_avx2.cpp,
// compiled with -mavx2): 8 pixels per instruction, the same float
// operations in the same order, so every mask bit is the SSE2 pass's. Plain
// types only, so that no inline function of another header is compiled
// into this file with AVX2 instructions and picked by the linker for
// baseline code.
#pragma once

#include <cstdint>

namespace surfinspect::link_row::avx2 {

// cur / up: the x, y, z planes (up may be null: the first row); masks:
// valid, west, north-west, north, north-east, `words` words each. Returns
// whether an infinite coordinate was seen. Call only where AVX2 runs.
bool RowBits(const float* const cur[3], const float* const up[3], bool diagonals, uint32_t words,
             float link_distance_sq, uint64_t* const masks[5]);

// The first of w points (x, y, z interleaved in `points`) into the planes
// x, y, z, in whole groups of 8 (3 loads, 5 shuffles and 3 stores each);
// returns how many it took (w rounded down to a multiple of 8). Call only
// where AVX2 runs.
uint32_t Transpose(const float* points, uint32_t w, float* x, float* y, float* z);

}  // namespace surfinspect::link_row::avx2
