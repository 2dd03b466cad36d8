// Sixteen points (x, y, z interleaved) into three registers of x, y and z:
// 3 loads and 6 two-source permutes. Include only in a file compiled with
// -mavx512f: the function has internal linkage, so no copy of it compiled
// with AVX-512 can be picked by the linker for code that runs without it.
#pragma once

#include <immintrin.h>

namespace surfinspect::avx512 {
namespace {

inline void Transpose16(const float* f, __m512& x, __m512& y, __m512& z) {
  // Point p's coordinate a is float 3p + a of the 48 loaded (a: 0-15, b:
  // 16-31, c: 32-47). Each plane takes its floats from a and b with one
  // two-source permute (indices 0-31), then the rest from c (indices 16-31
  // of the second permute's sources select c).
  const __m512i ab_x = _mm512_setr_epi32(0, 3, 6, 9, 12, 15, 18, 21, 24, 27, 30, 0, 0, 0, 0, 0);
  const __m512i ab_y = _mm512_setr_epi32(1, 4, 7, 10, 13, 16, 19, 22, 25, 28, 31, 0, 0, 0, 0, 0);
  const __m512i ab_z = _mm512_setr_epi32(2, 5, 8, 11, 14, 17, 20, 23, 26, 29, 0, 0, 0, 0, 0, 0);
  const __m512i c_x = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 17, 20, 23, 26, 29);
  const __m512i c_y = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 18, 21, 24, 27, 30);
  const __m512i c_z = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 16, 19, 22, 25, 28, 31);
  const __m512 a = _mm512_loadu_ps(f), b = _mm512_loadu_ps(f + 16), c = _mm512_loadu_ps(f + 32);
  x = _mm512_permutex2var_ps(_mm512_permutex2var_ps(a, ab_x, b), c_x, c);
  y = _mm512_permutex2var_ps(_mm512_permutex2var_ps(a, ab_y, b), c_y, c);
  z = _mm512_permutex2var_ps(_mm512_permutex2var_ps(a, ab_z, b), c_z, c);
}

// vfpclassps categories: quiet NaN, +inf, -inf, signalling NaN.
constexpr int kInfinite = 0x08 | 0x10;
constexpr int kNotFinite = 0x01 | kInfinite | 0x80;

// Lanes whose point has a coordinate that is not finite (NaN or infinite).
inline __mmask16 NotFinite(__m512 x, __m512 y, __m512 z) {
  return _mm512_fpclass_ps_mask(x, kNotFinite) | _mm512_fpclass_ps_mask(y, kNotFinite) |
         _mm512_fpclass_ps_mask(z, kNotFinite);
}

}  // namespace
}  // namespace surfinspect::avx512
