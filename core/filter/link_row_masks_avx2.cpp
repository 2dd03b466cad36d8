#include "core/filter/link_row_masks_avx2.h"

#include <immintrin.h>

namespace surfinspect::link_row::avx2 {
namespace {

// 8 link tests at once: PointsLinked's float operations in its order.
inline uint64_t Link8(__m256 px, __m256 py, __m256 pz, const float* bx, const float* by,
                      const float* bz, __m256 r2) {
  const __m256 dx = _mm256_sub_ps(px, _mm256_loadu_ps(bx));
  const __m256 dy = _mm256_sub_ps(py, _mm256_loadu_ps(by));
  const __m256 dz = _mm256_sub_ps(pz, _mm256_loadu_ps(bz));
  const __m256 d2 = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)),
                                  _mm256_mul_ps(dz, dz));
  // Ordered <=, as SSE2's cmpleps: NaN never links.
  return static_cast<uint64_t>(_mm256_movemask_ps(_mm256_cmp_ps(d2, r2, _CMP_LE_OQ)));
}

template <bool kAbove, bool kDiagonals>
bool Pass(const float* const cur[3], const float* const up[3], uint32_t words, float r2,
          uint64_t* const masks[5]) {
  const float *x = cur[0], *y = cur[1], *z = cur[2];
  const float *ux = up[0], *uy = up[1], *uz = up[2];
  const __m256 zero = _mm256_setzero_ps(), inf = _mm256_set1_ps(__builtin_inff()),
               r = _mm256_set1_ps(r2);
  const __m256 abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
  __m256 any_inf = zero;
  for (uint32_t k = 0; k < words; ++k) {
    uint64_t valid = 0, west = 0, north_west = 0, north = 0, north_east = 0;
    for (uint32_t j = 0; j < 64; j += 8) {
      const uint32_t i = 64 * k + j;
      const __m256 px = _mm256_loadu_ps(x + i), py = _mm256_loadu_ps(y + i),
                   pz = _mm256_loadu_ps(z + i);
      // 0 * NaN and 0 * inf are NaN: the sum is 0 only for a valid pixel.
      const __m256 s = _mm256_add_ps(
          _mm256_add_ps(_mm256_mul_ps(px, zero), _mm256_mul_ps(py, zero)), _mm256_mul_ps(pz, zero));
      const uint64_t valid8 = uint64_t(_mm256_movemask_ps(_mm256_cmp_ps(s, zero, _CMP_EQ_OQ)));
      valid |= valid8 << j;
      any_inf = _mm256_or_ps(
          any_inf, _mm256_or_ps(_mm256_cmp_ps(_mm256_and_ps(px, abs_mask), inf, _CMP_EQ_OQ),
                                _mm256_cmp_ps(_mm256_and_ps(py, abs_mask), inf, _CMP_EQ_OQ)));
      any_inf = _mm256_or_ps(any_inf, _mm256_cmp_ps(_mm256_and_ps(pz, abs_mask), inf, _CMP_EQ_OQ));
      // A pixel without data links to nothing: eight of them in a row (a
      // shadow, the background) skip the link tests, which are the pass's
      // float work.
      if (valid8 == 0) continue;
      west |= Link8(px, py, pz, x + i - 1, y + i - 1, z + i - 1, r) << j;
      if (kAbove) north |= Link8(px, py, pz, ux + i, uy + i, uz + i, r) << j;
      if (kDiagonals) {
        north_west |= Link8(px, py, pz, ux + i - 1, uy + i - 1, uz + i - 1, r) << j;
        north_east |= Link8(px, py, pz, ux + i + 1, uy + i + 1, uz + i + 1, r) << j;
      }
    }
    masks[0][k] = valid, masks[1][k] = west;
    masks[2][k] = north_west, masks[3][k] = north, masks[4][k] = north_east;
  }
  return _mm256_movemask_ps(any_inf) != 0;
}

}  // namespace

bool RowBits(const float* const cur[3], const float* const up[3], bool diagonals, uint32_t words,
             float link_distance_sq, uint64_t* const masks[5]) {
  if (!up) return Pass<false, false>(cur, cur, words, link_distance_sq, masks);
  if (diagonals) return Pass<true, true>(cur, up, words, link_distance_sq, masks);
  return Pass<true, false>(cur, up, words, link_distance_sq, masks);
}

void Transpose(const float* f, uint32_t w, float* x, float* y, float* z) {
  uint32_t i = 0;
  for (; i + 8 <= w; i += 8, f += 24) {
    // Lanes 0-3 hold points 0-3 and lanes 4-7 points 4-7, so each 128-bit
    // half is the SSE2 transpose of four points.
    const __m256 a = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(f)),
                                          _mm_loadu_ps(f + 12), 1);  // x0 y0 z0 x1 | x4 y4 z4 x5
    const __m256 b = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(f + 4)),
                                          _mm_loadu_ps(f + 16), 1);  // y1 z1 x2 y2 | y5 z5 x6 y6
    const __m256 c = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(f + 8)),
                                          _mm_loadu_ps(f + 20), 1);  // z2 x3 y3 z3 | z6 x7 y7 z7
    const __m256 xy = _mm256_shuffle_ps(b, c, _MM_SHUFFLE(2, 1, 3, 2));  // x2 y2 x3 y3
    const __m256 yz = _mm256_shuffle_ps(a, b, _MM_SHUFFLE(1, 0, 2, 1));  // y0 z0 y1 z1
    _mm256_storeu_ps(x + i, _mm256_shuffle_ps(a, xy, _MM_SHUFFLE(2, 0, 3, 0)));
    _mm256_storeu_ps(y + i, _mm256_shuffle_ps(yz, xy, _MM_SHUFFLE(3, 1, 2, 0)));
    _mm256_storeu_ps(z + i, _mm256_shuffle_ps(yz, c, _MM_SHUFFLE(3, 0, 3, 1)));
  }
  for (; i < w; ++i, f += 3) x[i] = f[0], y[i] = f[1], z[i] = f[2];
}

}  // namespace surfinspect::link_row::avx2
