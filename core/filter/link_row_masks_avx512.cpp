#include "core/filter/link_row_masks_avx512.h"

#include <immintrin.h>

#include "core/types/transpose16_avx512.h"

namespace surfinspect::link_row::avx512 {
namespace {

// 16 link tests at once: PointsLinked's float operations in its order
// (no FMA: the file is built with -ffp-contract=off), an ordered <= as
// SSE2's cmpleps, so NaN never links.
inline uint64_t Link16(__m512 px, __m512 py, __m512 pz, const float* bx, const float* by,
                       const float* bz, __m512 r2) {
  const __m512 dx = _mm512_sub_ps(px, _mm512_loadu_ps(bx));
  const __m512 dy = _mm512_sub_ps(py, _mm512_loadu_ps(by));
  const __m512 dz = _mm512_sub_ps(pz, _mm512_loadu_ps(bz));
  const __m512 d2 = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(dx, dx), _mm512_mul_ps(dy, dy)),
                                  _mm512_mul_ps(dz, dz));
  return _mm512_cmp_ps_mask(d2, r2, _CMP_LE_OQ);
}

using surfinspect::avx512::kInfinite;
using surfinspect::avx512::NotFinite;

template <bool kAbove, bool kDiagonals>
bool Pass(const float* const cur[3], const float* const up[3], uint32_t words, float r2,
          uint64_t* const masks[5]) {
  const float *x = cur[0], *y = cur[1], *z = cur[2];
  const float *ux = up[0], *uy = up[1], *uz = up[2];
  const __m512 r = _mm512_set1_ps(r2);
  __mmask16 any_inf = 0;
  for (uint32_t k = 0; k < words; ++k) {
    uint64_t valid = 0, west = 0, north_west = 0, north = 0, north_east = 0;
    for (uint32_t j = 0; j < 64; j += 16) {
      const uint32_t i = 64 * k + j;
      const __m512 px = _mm512_loadu_ps(x + i), py = _mm512_loadu_ps(y + i),
                   pz = _mm512_loadu_ps(z + i);
      // Valid: every coordinate finite, which is what the other passes'
      // x * 0 + y * 0 + z * 0 == 0 tests.
      const __mmask16 bad = NotFinite(px, py, pz);
      if (bad != 0) {
        any_inf |= _mm512_fpclass_ps_mask(px, kInfinite) | _mm512_fpclass_ps_mask(py, kInfinite) |
                   _mm512_fpclass_ps_mask(pz, kInfinite);
        if (bad == 0xffff) continue;  // no data links to nothing (as in the AVX2 pass)
      }
      valid |= uint64_t{static_cast<uint16_t>(~bad)} << j;
      west |= Link16(px, py, pz, x + i - 1, y + i - 1, z + i - 1, r) << j;
      if (kAbove) north |= Link16(px, py, pz, ux + i, uy + i, uz + i, r) << j;
      if (kDiagonals) {
        north_west |= Link16(px, py, pz, ux + i - 1, uy + i - 1, uz + i - 1, r) << j;
        north_east |= Link16(px, py, pz, ux + i + 1, uy + i + 1, uz + i + 1, r) << j;
      }
    }
    masks[0][k] = valid, masks[1][k] = west;
    masks[2][k] = north_west, masks[3][k] = north, masks[4][k] = north_east;
  }
  return any_inf != 0;
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
  for (; i + 16 <= w; i += 16, f += 48) {
    __m512 px, py, pz;
    surfinspect::avx512::Transpose16(f, px, py, pz);
    _mm512_storeu_ps(x + i, px);
    _mm512_storeu_ps(y + i, py);
    _mm512_storeu_ps(z + i, pz);
  }
  for (; i < w; ++i, f += 3) x[i] = f[0], y[i] = f[1], z[i] = f[2];
}

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
