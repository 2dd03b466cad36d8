#include "core/distance/morton_order_avx512.h"

#include <immintrin.h>

#include "core/types/transpose16_avx512.h"

namespace surfinspect::morton::avx512 {
namespace {

using surfinspect::avx512::NotFinite;
using surfinspect::avx512::Transpose16;

// The cells of 8 coordinates: clamp((c - min) * scale, 0, 1023), truncated,
// as the scalar loop computes them in double.
inline __m256i Cells(__m256 c, __m512d min, __m512d scale) {
  __m512d v = _mm512_mul_pd(_mm512_sub_pd(_mm512_cvtps_pd(c), min), scale);
  v = _mm512_min_pd(_mm512_max_pd(v, _mm512_setzero_pd()), _mm512_set1_pd(1023.0));
  return _mm512_cvttpd_epi32(v);
}

// The spread cells of 16 coordinates.
inline __m512i SpreadCells(__m512 c, __m512d min, __m512d scale, const uint32_t* spread) {
  const __m256i lo = Cells(_mm512_castps512_ps256(c), min, scale);
  const __m256i hi = Cells(_mm512_extractf32x8_ps(c, 1), min, scale);
  const __m512i cells = _mm512_inserti64x4(_mm512_castsi256_si512(lo), hi, 1);
  return _mm512_i32gather_epi32(cells, reinterpret_cast<const int*>(spread), 4);
}

}  // namespace

std::size_t ExtendBounds(const float* xyz, std::size_t n, float lo[3], float hi[3]) {
  __m512 vlo[3], vhi[3];
  for (int a = 0; a < 3; ++a) vlo[a] = _mm512_set1_ps(lo[a]), vhi[a] = _mm512_set1_ps(hi[a]);
  std::size_t i = 0;
  for (; i + 16 <= n; i += 16) {
    __m512 p[3];
    Transpose16(xyz + 3 * i, p[0], p[1], p[2]);
    const __mmask16 valid = static_cast<__mmask16>(~NotFinite(p[0], p[1], p[2]));
    for (int a = 0; a < 3; ++a) {
      vlo[a] = _mm512_mask_min_ps(vlo[a], valid, vlo[a], p[a]);
      vhi[a] = _mm512_mask_max_ps(vhi[a], valid, vhi[a], p[a]);
    }
  }
  for (int a = 0; a < 3; ++a) {
    alignas(64) float l[16], h[16];
    _mm512_store_ps(l, vlo[a]);
    _mm512_store_ps(h, vhi[a]);
    for (int k = 0; k < 16; ++k) {
      lo[a] = l[k] < lo[a] ? l[k] : lo[a];
      hi[a] = h[k] > hi[a] ? h[k] : hi[a];
    }
  }
  return i;
}

std::size_t Codes(const float* xyz, std::size_t n, uint32_t first, const double min[3],
                  double scale, const uint32_t* spread, uint64_t* items) {
  const __m512d s = _mm512_set1_pd(scale);
  const __m512i invalid = _mm512_set1_epi32(1 << 30);
  const __m512i lanes = _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7);
  std::size_t i = 0;
  for (; i + 16 <= n; i += 16) {
    __m512 p[3];
    Transpose16(xyz + 3 * i, p[0], p[1], p[2]);
    __m512i code = SpreadCells(p[0], _mm512_set1_pd(min[0]), s, spread);
    code = _mm512_or_si512(
        code, _mm512_slli_epi32(SpreadCells(p[1], _mm512_set1_pd(min[1]), s, spread), 1));
    code = _mm512_or_si512(
        code, _mm512_slli_epi32(SpreadCells(p[2], _mm512_set1_pd(min[2]), s, spread), 2));
    // An invalid point's cells are in the table too (max(NaN, 0) is 0, as
    // vmaxpd returns its second operand on NaN); its code is replaced here.
    code = _mm512_mask_mov_epi32(code, NotFinite(p[0], p[1], p[2]), invalid);
    const __m512i index = _mm512_add_epi64(_mm512_set1_epi64(first + i), lanes);
    const __m512i code_lo = _mm512_cvtepu32_epi64(_mm512_castsi512_si256(code));
    const __m512i code_hi = _mm512_cvtepu32_epi64(_mm512_extracti64x4_epi64(code, 1));
    _mm512_storeu_si512(items + i, _mm512_or_si512(_mm512_slli_epi64(code_lo, 32), index));
    _mm512_storeu_si512(items + i + 8,
                        _mm512_or_si512(_mm512_slli_epi64(code_hi, 32),
                                        _mm512_add_epi64(index, _mm512_set1_epi64(8))));
  }
  return i;
}

}  // namespace surfinspect::morton::avx512
