#include "core/filter/link_row_masks_avx512.h"

#include <immintrin.h>

#include "core/filter/link_row_pass.h"
#include "core/types/transpose16_avx512.h"

namespace surfinspect::link_row::avx512 {
namespace {

// The row pass's operations on 16 floats, compared into mask registers.
struct Avx512 {
  using Vec = __m512;
  static constexpr int kWidth = 16;
  static Vec Load(const float* p) { return _mm512_loadu_ps(p); }
  static void Store(float* p, Vec v) { _mm512_storeu_ps(p, v); }
  static void Transpose(const float* points, Vec& x, Vec& y, Vec& z) {
    surfinspect::avx512::Transpose16(points, x, y, z);
  }
  // before's lane 15, then v's lanes 0-14: each lane's west neighbour.
  static Vec ShiftIn(Vec v, Vec before) {
    return _mm512_castsi512_ps(
        _mm512_alignr_epi32(_mm512_castps_si512(v), _mm512_castps_si512(before), 15));
  }
  static Vec Set1(float v) { return _mm512_set1_ps(v); }
  static Vec Sub(Vec a, Vec b) { return _mm512_sub_ps(a, b); }
  static Vec Mul(Vec a, Vec b) { return _mm512_mul_ps(a, b); }
  static Vec Add(Vec a, Vec b) { return _mm512_add_ps(a, b); }
  // Ordered <=, as SSE2's cmpleps: NaN never links.
  static uint64_t LessEqual(Vec a, Vec b) { return _mm512_cmp_ps_mask(a, b, _CMP_LE_OQ); }
  // vfpclassps: what the other sets' x * 0 + y * 0 + z * 0 != 0 tests.
  static uint64_t NotFinite(Vec x, Vec y, Vec z) { return surfinspect::avx512::NotFinite(x, y, z); }
  static uint64_t Infinite(Vec x, Vec y, Vec z) {
    using surfinspect::avx512::kInfinite;
    return _mm512_fpclass_ps_mask(x, kInfinite) | _mm512_fpclass_ps_mask(y, kInfinite) |
           _mm512_fpclass_ps_mask(z, kInfinite);
  }
};

// The least (kMax: greatest) of the 16 lanes, by halving.
template <bool kMax>
float Reduce(__m512 v) {
  auto op8 = [](__m256 a, __m256 b) { return kMax ? _mm256_max_ps(a, b) : _mm256_min_ps(a, b); };
  auto op4 = [](__m128 a, __m128 b) { return kMax ? _mm_max_ps(a, b) : _mm_min_ps(a, b); };
  const __m256 h = op8(_mm512_castps512_ps256(v), _mm512_extractf32x8_ps(v, 1));
  __m128 q = op4(_mm256_castps256_ps128(h), _mm256_extractf128_ps(h, 1));
  q = op4(q, _mm_movehl_ps(q, q));
  q = op4(q, _mm_shuffle_ps(q, q, 1));
  return _mm_cvtss_f32(q);
}

}  // namespace

bool RowBits(const float* const cur[3], const float* const up[3], bool diagonals, uint32_t words,
             float link_distance_sq, uint64_t* const masks[5]) {
  return RowBitsOf<Avx512>(cur, up, diagonals, words, link_distance_sq, masks);
}

bool TransposedRowBits(const float* points, uint32_t whole, float* const cur[3],
                       const float* const up[3], bool diagonals, uint32_t words,
                       float link_distance_sq, uint64_t* const masks[5], const float* ahead) {
  return TransposedRowBitsOf<Avx512>(points, whole, cur, up, diagonals, words, link_distance_sq,
                                     masks, ahead);
}

uint32_t Transpose(const float* f, uint32_t w, float* x, float* y, float* z) {
  uint32_t i = 0;
  for (; i + 16 <= w; i += 16, f += 48) {
    __m512 px, py, pz;
    surfinspect::avx512::Transpose16(f, px, py, pz);
    _mm512_storeu_ps(x + i, px);
    _mm512_storeu_ps(y + i, py);
    _mm512_storeu_ps(z + i, pz);
  }
  return i;
}

bool BoundsOfRun(const float* const row[3], uint32_t first, uint32_t last, float lo[3],
                 float hi[3]) {
  const __m512 inf = _mm512_set1_ps(__builtin_inff()),
               minus_inf = _mm512_set1_ps(-__builtin_inff());
  __m512 vlo[3] = {inf, inf, inf}, vhi[3] = {minus_inf, minus_inf, minus_inf};
  uint32_t i = first;
  for (; i + 15 <= last; i += 16)
    for (int a = 0; a < 3; ++a) {
      const __m512 q = _mm512_loadu_ps(row[a] + i);
      vlo[a] = _mm512_min_ps(vlo[a], q);
      vhi[a] = _mm512_max_ps(vhi[a], q);
    }
  if (i <= last) {
    // The tail's other lanes read as +inf for the minimum, -inf for the
    // maximum; a masked load touches no memory outside its mask.
    const auto tail = static_cast<__mmask16>((1u << (last + 1 - i)) - 1);
    for (int a = 0; a < 3; ++a) {
      vlo[a] = _mm512_min_ps(vlo[a], _mm512_mask_loadu_ps(inf, tail, row[a] + i));
      vhi[a] = _mm512_max_ps(vhi[a], _mm512_mask_loadu_ps(minus_inf, tail, row[a] + i));
    }
  }
  for (int a = 0; a < 3; ++a) {
    lo[a] = Reduce<false>(vlo[a]);
    hi[a] = Reduce<true>(vhi[a]);
    if (lo[a] == 0 || hi[a] == 0) return false;
  }
  return true;
}

}  // namespace surfinspect::link_row::avx512
