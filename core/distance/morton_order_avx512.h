// The AVX-512 build of morton_order.cpp's bounds and codes (compiled with
// -mavx512f -mavx512dq -ffp-contract=off): 16 points per instruction, the
// codes computed with the scalar loop's double operations in its order, so
// every code is the scalar one. Plain types only, so that no inline
// function of another header is compiled here with AVX-512 instructions
// and picked by the linker for baseline code.
#pragma once

#include <cstddef>
#include <cstdint>

namespace surfinspect::morton::avx512 {

// Both take whole groups of 16 of the n points at `xyz` (x, y, z
// interleaved) and return how many points they took (n rounded down to a
// multiple of 16); the caller's scalar loop does the rest.

// Widens lo / hi (per axis) to the valid points (every coordinate finite).
std::size_t ExtendBounds(const float* xyz, std::size_t n, float lo[3], float hi[3]);

// items[i] = code << 32 | (first + i): the Morton code of the cell
// clamp((p - min) * scale, 0, 1023) per axis, its bits spread by `spread`
// (1024 entries), or 2^30 for an invalid point.
std::size_t Codes(const float* xyz, std::size_t n, uint32_t first, const double min[3],
                  double scale, const uint32_t* spread, uint64_t* items);

}  // namespace surfinspect::morton::avx512
