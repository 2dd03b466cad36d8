#include "core/filter/link_row_masks_avx2.h"

#include <immintrin.h>

#include "core/filter/link_row_pass.h"

namespace surfinspect::link_row::avx2 {
namespace {

// The row pass's operations on 8 floats.
struct Avx2 {
  using Vec = __m256;
  static constexpr int kWidth = 8;
  static Vec Load(const float* p) { return _mm256_loadu_ps(p); }
  static Vec Set1(float v) { return _mm256_set1_ps(v); }
  static Vec Sub(Vec a, Vec b) { return _mm256_sub_ps(a, b); }
  static Vec Mul(Vec a, Vec b) { return _mm256_mul_ps(a, b); }
  static Vec Add(Vec a, Vec b) { return _mm256_add_ps(a, b); }
  // Ordered <=, as SSE2's cmpleps: NaN never links.
  static uint64_t LessEqual(Vec a, Vec b) {
    return static_cast<uint64_t>(_mm256_movemask_ps(_mm256_cmp_ps(a, b, _CMP_LE_OQ)));
  }
  // 0 * NaN and 0 * inf are NaN: the sum is 0 only for a valid pixel.
  static uint64_t NotFinite(Vec x, Vec y, Vec z) {
    const Vec zero = _mm256_setzero_ps();
    const Vec s = Add(Add(Mul(x, zero), Mul(y, zero)), Mul(z, zero));
    return static_cast<uint64_t>(_mm256_movemask_ps(_mm256_cmp_ps(s, zero, _CMP_NEQ_UQ)));
  }
  static uint64_t Infinite(Vec x, Vec y, Vec z) {
    const Vec abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
    const Vec inf = _mm256_set1_ps(__builtin_inff());
    auto is_inf = [&](Vec v) { return _mm256_cmp_ps(_mm256_and_ps(v, abs_mask), inf, _CMP_EQ_OQ); };
    return static_cast<uint64_t>(
        _mm256_movemask_ps(_mm256_or_ps(_mm256_or_ps(is_inf(x), is_inf(y)), is_inf(z))));
  }
};

}  // namespace

bool RowBits(const float* const cur[3], const float* const up[3], bool diagonals, uint32_t words,
             float link_distance_sq, uint64_t* const masks[5]) {
  return RowBitsOf<Avx2>(cur, up, diagonals, words, link_distance_sq, masks);
}

uint32_t Transpose(const float* f, uint32_t w, float* x, float* y, float* z) {
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
  return i;
}

}  // namespace surfinspect::link_row::avx2
