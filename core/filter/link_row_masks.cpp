#include "core/filter/link_row_masks.h"

#include <algorithm>
#include <cmath>

#include "core/filter/link_clustering.h"
#include "core/filter/link_row_masks_avx2.h"
#include "core/filter/link_row_masks_avx512.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace surfinspect::link_row {

RowIsa ResolveRowIsa(RowIsa isa) {
  if (isa != RowIsa::kAuto) return isa;
  if (RowIsaSupported(RowIsa::kAvx512)) return RowIsa::kAvx512;
  return RowIsaSupported(RowIsa::kAvx2) ? RowIsa::kAvx2 : RowIsa::kSse2;
}

namespace {

// Points [i, w) into the SoA row, 4 at a time with SSE2 (3 loads, 7
// shuffles), then one by one.
void TransposeFrom(const Eigen::Vector3f* pts, uint32_t i, uint32_t w, RowSoA& row) {
  float* __restrict x = row.c(0);
  float* __restrict y = row.c(1);
  float* __restrict z = row.c(2);
  const float* f = pts[0].data() + 3 * std::size_t{i};
#if defined(__SSE2__)
  for (; i + 4 <= w; i += 4, f += 12) {
    const __m128 a = _mm_loadu_ps(f), b = _mm_loadu_ps(f + 4), c = _mm_loadu_ps(f + 8);
    _mm_storeu_ps(x + i, _mm_shuffle_ps(a, _mm_shuffle_ps(b, c, _MM_SHUFFLE(1, 1, 2, 2)),
                                        _MM_SHUFFLE(2, 0, 3, 0)));
    _mm_storeu_ps(y + i, _mm_shuffle_ps(_mm_shuffle_ps(a, b, _MM_SHUFFLE(0, 0, 1, 1)),
                                        _mm_shuffle_ps(b, c, _MM_SHUFFLE(2, 2, 3, 3)),
                                        _MM_SHUFFLE(2, 0, 2, 0)));
    _mm_storeu_ps(z + i, _mm_shuffle_ps(_mm_shuffle_ps(a, b, _MM_SHUFFLE(1, 1, 2, 2)),
                                        _mm_shuffle_ps(c, c, _MM_SHUFFLE(3, 3, 0, 0)),
                                        _MM_SHUFFLE(2, 0, 2, 0)));
  }
#endif
  for (; i < w; ++i, f += 3) x[i] = f[0], y[i] = f[1], z[i] = f[2];
}

}  // namespace

// Copies w points into the SoA row: the wider sets take whole groups of 8
// or 16 points, SSE2 and the scalar loop finish the row.
void Transpose(const Eigen::Vector3f* pts, uint32_t w, RowSoA& row, RowIsa isa) {
  uint32_t i = 0;
  isa = ResolveRowIsa(isa);
  const float* f = pts[0].data();
  if (isa == RowIsa::kAvx512) i = avx512::Transpose(f, w, row.c(0), row.c(1), row.c(2));
  if (isa == RowIsa::kAvx2) i = avx2::Transpose(f, w, row.c(0), row.c(1), row.c(2));
  TransposeFrom(pts, i, w, row);
}

bool TransposeAndComputeMasks(const Eigen::Vector3f* pts, uint32_t w, RowSoA& cur, const RowSoA* up,
                              bool diagonals, uint32_t words, float link_distance_sq,
                              const RowMasks& masks, RowIsa isa, const Eigen::Vector3f* next) {
  isa = ResolveRowIsa(isa);
  if (isa != RowIsa::kAvx512) {
    Transpose(pts, w, cur, isa);
    if (next) {
      // The next row streams in while this one's links are tested: without
      // it the AVX2 transpose is bound by load latency, as
      // bench/link_clustering_bench.cpp shows. The AVX-512 pass prefetches
      // group by group instead (link_row_pass.h).
      const char* bytes = reinterpret_cast<const char*>(next);
      for (std::size_t b = 0; b < std::size_t{w} * sizeof(Eigen::Vector3f); b += 64)
        __builtin_prefetch(bytes + b);
    }
    return ComputeMasks(cur, up, diagonals, words, link_distance_sq, masks, isa);
  }
  // The last partial group goes in first; the fused pass reads it back.
  const uint32_t whole = w / 16 * 16;
  TransposeFrom(pts, whole, w, cur);
  float* const c[3] = {cur.c(0), cur.c(1), cur.c(2)};
  const float* const u[3] = {up ? up->c(0) : nullptr, up ? up->c(1) : nullptr,
                             up ? up->c(2) : nullptr};
  uint64_t* const m[5] = {masks.valid, masks.west, masks.north_west, masks.north, masks.north_east};
  return avx512::TransposedRowBits(pts[0].data(), whole, c, up ? u : nullptr, diagonals, words,
                                   link_distance_sq, m, next ? next[0].data() : nullptr);
}

namespace {

#if defined(__SSE2__)
// 4 link tests at once, the float operations of PointsLinked in its order.
inline uint64_t Link4(__m128 px, __m128 py, __m128 pz, const float* bx, const float* by,
                      const float* bz, __m128 r2) {
  const __m128 dx = _mm_sub_ps(px, _mm_loadu_ps(bx));
  const __m128 dy = _mm_sub_ps(py, _mm_loadu_ps(by));
  const __m128 dz = _mm_sub_ps(pz, _mm_loadu_ps(bz));
  const __m128 d2 =
      _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
  return static_cast<uint64_t>(_mm_movemask_ps(_mm_cmple_ps(d2, r2)));
}
#endif

// One pass over a row in SoA form: valid bits (all coordinates finite, as
// 0 * NaN and 0 * inf are NaN), west links and, with a row above, north
// (and north-west / north-east) links; NaN never links. Returns whether an
// infinite coordinate was seen, which the cloud contract forbids.
template <bool kAbove, bool kDiagonals>
bool RowBits(const RowSoA& cur, const RowSoA& up, uint32_t words, float r2, const RowMasks& m) {
  const float *x = cur.c(0), *y = cur.c(1), *z = cur.c(2);
  const float *ux = up.c(0), *uy = up.c(1), *uz = up.c(2);
#if defined(__SSE2__)
  const __m128 zero = _mm_setzero_ps(), inf = _mm_set1_ps(INFINITY), r = _mm_set1_ps(r2);
  const __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
  __m128 any_inf = zero;
  for (uint32_t k = 0; k < words; ++k) {
    uint64_t valid = 0, west = 0, north_west = 0, north = 0, north_east = 0;
    for (uint32_t j = 0; j < 64; j += 4) {
      const uint32_t i = 64 * k + j;
      const __m128 px = _mm_loadu_ps(x + i), py = _mm_loadu_ps(y + i), pz = _mm_loadu_ps(z + i);
      const __m128 s =
          _mm_add_ps(_mm_add_ps(_mm_mul_ps(px, zero), _mm_mul_ps(py, zero)), _mm_mul_ps(pz, zero));
      const uint64_t valid4 = uint64_t(_mm_movemask_ps(_mm_cmpeq_ps(s, zero)));
      valid |= valid4 << j;
      any_inf = _mm_or_ps(any_inf, _mm_or_ps(_mm_cmpeq_ps(_mm_and_ps(px, abs_mask), inf),
                                             _mm_cmpeq_ps(_mm_and_ps(py, abs_mask), inf)));
      any_inf = _mm_or_ps(any_inf, _mm_cmpeq_ps(_mm_and_ps(pz, abs_mask), inf));
      if (valid4 == 0) continue;  // no data links to nothing (as in the AVX2 pass)
      west |= Link4(px, py, pz, x + i - 1, y + i - 1, z + i - 1, r) << j;
      if (kAbove) north |= Link4(px, py, pz, ux + i, uy + i, uz + i, r) << j;
      if (kDiagonals) {
        north_west |= Link4(px, py, pz, ux + i - 1, uy + i - 1, uz + i - 1, r) << j;
        north_east |= Link4(px, py, pz, ux + i + 1, uy + i + 1, uz + i + 1, r) << j;
      }
    }
    m.valid[k] = valid, m.west[k] = west;
    m.north_west[k] = north_west, m.north[k] = north, m.north_east[k] = north_east;
  }
  return _mm_movemask_ps(any_inf) != 0;
#else
  bool any_inf = false;
  // Neighbours through shifted pointers: index i - 1 would wrap at i = 0.
  auto at = [](const float* a, const float* b, const float* c, int shift, uint32_t i) {
    return Eigen::Vector3f((a + shift)[i], (b + shift)[i], (c + shift)[i]);
  };
  for (uint32_t k = 0; k < words; ++k) {
    uint64_t valid = 0, west = 0, north_west = 0, north = 0, north_east = 0;
    for (uint32_t j = 0; j < 64; ++j) {
      const uint32_t i = 64 * k + j;
      const Eigen::Vector3f q = at(x, y, z, 0, i);
      valid |= uint64_t(q.x() * 0.f + q.y() * 0.f + q.z() * 0.f == 0.f) << j;
      any_inf |= q.array().isInf().any();
      west |= uint64_t(PointsLinked(q, at(x, y, z, -1, i), r2)) << j;
      if (kAbove) north |= uint64_t(PointsLinked(q, at(ux, uy, uz, 0, i), r2)) << j;
      if (kDiagonals) {
        north_west |= uint64_t(PointsLinked(q, at(ux, uy, uz, -1, i), r2)) << j;
        north_east |= uint64_t(PointsLinked(q, at(ux, uy, uz, 1, i), r2)) << j;
      }
    }
    m.valid[k] = valid, m.west[k] = west;
    m.north_west[k] = north_west, m.north[k] = north, m.north_east[k] = north_east;
  }
  return any_inf;
#endif
}

}  // namespace

bool RowIsaSupported(RowIsa isa) {
  // __builtin_cpu_supports also checks that the OS saves the registers.
  static const bool avx2 = __builtin_cpu_supports("avx2");
  static const bool avx512 =
      __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq");
  if (isa == RowIsa::kAvx2) return avx2;
  if (isa == RowIsa::kAvx512) return avx512;
  return true;
}

bool ComputeMasks(const RowSoA& cur, const RowSoA* up, bool diagonals, uint32_t words,
                  float link_distance_sq, const RowMasks& masks, RowIsa isa) {
  isa = ResolveRowIsa(isa);
  if (isa != RowIsa::kSse2) {
    const float* const c[3] = {cur.c(0), cur.c(1), cur.c(2)};
    const float* const u[3] = {up ? up->c(0) : nullptr, up ? up->c(1) : nullptr,
                               up ? up->c(2) : nullptr};
    uint64_t* const m[5] = {masks.valid, masks.west, masks.north_west, masks.north,
                            masks.north_east};
    return (isa == RowIsa::kAvx512 ? avx512::RowBits : avx2::RowBits)(
        c, up ? u : nullptr, diagonals, words, link_distance_sq, m);
  }
  if (!up) return RowBits<false, false>(cur, cur, words, link_distance_sq, masks);
  if (diagonals) return RowBits<true, true>(cur, *up, words, link_distance_sq, masks);
  return RowBits<true, false>(cur, *up, words, link_distance_sq, masks);
}

void RunBounds(const RowMasks& m, uint32_t words, uint64_t* starts, uint64_t* ends) {
  for (uint32_t k = 0; k < words; ++k) {
    const uint64_t west_of_next = (m.west[k] >> 1) | (k + 1 < words ? m.west[k + 1] << 63 : 0);
    starts[k] = m.valid[k] & ~m.west[k];
    ends[k] = m.valid[k] & ~west_of_next;
  }
}

// Bounds of a run of at least 8 (all valid) pixels. Each axis keeps the
// lanes of a one-axis-at-a-time reduction (4 lanes, then lane 0-3 in pairs,
// then the scalar tail), so the result is that reduction's bit for bit, the
// sign of a zero included; interleaving the axes runs their three min/max
// dependency chains side by side instead of one after another, which the
// grid rows of bench/link_clustering_bench.cpp show. With AVX-512 the run
// goes 16 lanes at a time, and through this reduction where a bound is zero.
void BoundsOfLongRun(const RowSoA& row, uint32_t first, uint32_t last, float lo_out[3],
                     float hi_out[3], RowIsa isa) {
  if (ResolveRowIsa(isa) == RowIsa::kAvx512) {
    const float* const planes[3] = {row.c(0), row.c(1), row.c(2)};
    if (avx512::BoundsOfRun(planes, first, last, lo_out, hi_out)) return;
  }
  uint32_t i = first;
#if defined(__SSE2__)
  __m128 vlo[3], vhi[3];
  for (int a = 0; a < 3; ++a) vlo[a] = vhi[a] = _mm_loadu_ps(row.c(a) + i);
  for (i += 4; i + 3 <= last; i += 4)
    for (int a = 0; a < 3; ++a) {
      const __m128 q = _mm_loadu_ps(row.c(a) + i);
      vlo[a] = _mm_min_ps(vlo[a], q);
      vhi[a] = _mm_max_ps(vhi[a], q);
    }
  for (int a = 0; a < 3; ++a) {
    alignas(16) float l[4], h[4];
    _mm_store_ps(l, vlo[a]);
    _mm_store_ps(h, vhi[a]);
    lo_out[a] = std::min(std::min(l[0], l[1]), std::min(l[2], l[3]));
    hi_out[a] = std::max(std::max(h[0], h[1]), std::max(h[2], h[3]));
  }
#else
  for (int a = 0; a < 3; ++a) lo_out[a] = hi_out[a] = row.c(a)[i];
#endif
  for (; i <= last; ++i)
    for (int a = 0; a < 3; ++a) {
      lo_out[a] = std::min(lo_out[a], row.c(a)[i]);
      hi_out[a] = std::max(hi_out[a], row.c(a)[i]);
    }
}

}  // namespace surfinspect::link_row
