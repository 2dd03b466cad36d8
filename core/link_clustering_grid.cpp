#include "core/link_clustering_grid.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "absl/strings/str_cat.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace surfinspect {
namespace {

constexpr int32_t kInvalid = LinkClusteringResult::kInvalid;
constexpr uint32_t kNone = UINT32_MAX;

// A maximal chain of west-linked valid pixels in one row, with its 3D bounds.
struct Run {
  uint32_t row, first_col, last_col;
  float lo[3], hi[3];
  Eigen::Map<const Eigen::Vector3f> min() const { return Eigen::Map<const Eigen::Vector3f>(lo); }
  Eigen::Map<const Eigen::Vector3f> max() const { return Eigen::Map<const Eigen::Vector3f>(hi); }
};

// One row as structure-of-arrays, padded with NaN on both sides to a whole
// number of 64-bit mask words: a link to a pixel outside the grid compares
// NaN and is false with no bounds test.
struct RowSoA {
  std::vector<float> buf[3];
  explicit RowSoA(uint32_t padded) {
    for (auto& b : buf) b.assign(padded + 2, NAN);
  }
  float* c(int a) { return buf[a].data() + 1; }
  const float* c(int a) const { return buf[a].data() + 1; }
};

// Copies w points into the SoA row (SSE2: 4 points = 3 loads, 7 shuffles).
void Transpose(const Eigen::Vector3f* pts, uint32_t w, RowSoA& row) {
  float* __restrict x = row.c(0);
  float* __restrict y = row.c(1);
  float* __restrict z = row.c(2);
  const float* f = pts[0].data();
  uint32_t i = 0;
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

// Per-row bit masks, bit j of word k for pixel 64k + j.
struct RowMasks {
  uint64_t *valid, *west, *north_west, *north, *north_east;
};

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
      const __m128 s = _mm_add_ps(_mm_add_ps(_mm_mul_ps(px, zero), _mm_mul_ps(py, zero)),
                                  _mm_mul_ps(pz, zero));
      valid |= uint64_t(_mm_movemask_ps(_mm_cmpeq_ps(s, zero))) << j;
      any_inf = _mm_or_ps(any_inf, _mm_or_ps(_mm_cmpeq_ps(_mm_and_ps(px, abs_mask), inf),
                                             _mm_cmpeq_ps(_mm_and_ps(py, abs_mask), inf)));
      any_inf = _mm_or_ps(any_inf, _mm_cmpeq_ps(_mm_and_ps(pz, abs_mask), inf));
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
  const float r2f = r2;
  auto p = [](const float* a, const float* b, const float* c, uint32_t i) {
    return Eigen::Vector3f(a[i], b[i], c[i]);
  };
  for (uint32_t k = 0; k < words; ++k) {
    uint64_t valid = 0, west = 0, north_west = 0, north = 0, north_east = 0;
    for (uint32_t j = 0; j < 64; ++j) {
      const uint32_t i = 64 * k + j;
      const Eigen::Vector3f q = p(x, y, z, i);
      valid |= uint64_t(q.x() * 0.f + q.y() * 0.f + q.z() * 0.f == 0.f) << j;
      any_inf |= q.array().isInf().any();
      west |= uint64_t(PointsLinked(q, p(x, y, z, i - 1), r2f)) << j;
      if (kAbove) north |= uint64_t(PointsLinked(q, p(ux, uy, uz, i), r2f)) << j;
      if (kDiagonals) {
        north_west |= uint64_t(PointsLinked(q, p(ux, uy, uz, i - 1), r2f)) << j;
        north_east |= uint64_t(PointsLinked(q, p(ux, uy, uz, i + 1), r2f)) << j;
      }
    }
    m.valid[k] = valid, m.west[k] = west;
    m.north_west[k] = north_west, m.north[k] = north, m.north_east[k] = north_east;
  }
  return any_inf;
#endif
}

// First set bit at index >= from, or kNone.
uint32_t NextBit(const uint64_t* bits, uint32_t words, uint32_t from) {
  uint32_t k = from / 64;
  if (k >= words) return kNone;
  uint64_t w = bits[k] & (~uint64_t{0} << (from % 64));
  while (w == 0) {
    if (++k == words) return kNone;
    w = bits[k];
  }
  return 64 * k + static_cast<uint32_t>(__builtin_ctzll(w));
}

// Union-find over run indices; parent[r] <= r always (the smaller root wins),
// which pass 2 relies on. Path halving.
int32_t Find(std::vector<int32_t>& parent, int32_t i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}
void Union(std::vector<int32_t>& parent, int32_t a, int32_t b) {
  a = Find(parent, a);
  b = Find(parent, b);
  if (a < b) parent[b] = a;
  else if (b < a) parent[a] = b;
}

// Bounds of the (all valid) pixels first..last of the row.
void RunBounds(const RowSoA& row, uint32_t first, uint32_t last, Run& run) {
  for (int a = 0; a < 3; ++a) {
    const float* v = row.c(a);
    uint32_t i = first;
    float lo = v[i], hi = v[i];
#if defined(__SSE2__)
    if (last - first >= 7) {
      __m128 vlo = _mm_loadu_ps(v + i), vhi = vlo;
      for (i += 4; i + 3 <= last; i += 4) {
        const __m128 q = _mm_loadu_ps(v + i);
        vlo = _mm_min_ps(vlo, q);
        vhi = _mm_max_ps(vhi, q);
      }
      alignas(16) float l[4], h[4];
      _mm_store_ps(l, vlo);
      _mm_store_ps(h, vhi);
      lo = std::min(std::min(l[0], l[1]), std::min(l[2], l[3]));
      hi = std::max(std::max(h[0], h[1]), std::max(h[2], h[3]));
    }
#endif
    for (; i <= last; ++i) {
      lo = std::min(lo, v[i]);
      hi = std::max(hi, v[i]);
    }
    run.lo[a] = lo;
    run.hi[a] = hi;
  }
}

}  // namespace

absl::Status ClusterLinksOrganized(const PointCloud& cloud,
                                   const LinkClusteringSettings& settings,
                                   LinkClusteringResult& result,
                                   const std::atomic<bool>* cancel) {
  if (auto st = internal::CheckInput(cloud, settings); !st.ok()) return st;
  const uint32_t w = cloud.width, h = cloud.height;
  const uint32_t words = (w + 63) / 64;
  const float r2 = LinkDistanceSquared(settings.link_distance_mm);
  const bool eight = settings.connectivity == 8;

  RowSoA rows[2] = {RowSoA(64 * words), RowSoA(64 * words)};
  // Masks: valid, west, north-west, north, north-east, run starts, run ends.
  std::vector<uint64_t> masks(7 * std::size_t{words});
  const RowMasks m = {masks.data(), masks.data() + words, masks.data() + 2 * words,
                      masks.data() + 3 * words, masks.data() + 4 * words};
  uint64_t* const vertical[3] = {m.north_west, m.north, m.north_east};
  uint64_t* starts = masks.data() + 5 * words;
  uint64_t* ends = masks.data() + 6 * words;
  std::vector<int32_t> run_of[2] = {std::vector<int32_t>(w), std::vector<int32_t>(w)};
  std::vector<Run> runs;
  std::vector<int32_t> parent;
  runs.reserve(4 * std::size_t{h});
  parent.reserve(4 * std::size_t{h});

  // Pass 1: runs and their unions, row by row.
  for (uint32_t r = 0; r < h; ++r) {
    if (cancel && cancel->load(std::memory_order_relaxed))
      return absl::CancelledError("link clustering: cancelled");
    RowSoA& cur = rows[r & 1];
    const RowSoA& up = rows[(r + 1) & 1];
    Transpose(&cloud.points[std::size_t{r} * w], w, cur);
    if (r + 1 < h) {
      // The next row streams in while this one is labelled: the transpose
      // is otherwise bound by load latency, not bandwidth (measured).
      const char* next = reinterpret_cast<const char*>(&cloud.points[std::size_t{r + 1} * w]);
      for (std::size_t b = 0; b < std::size_t{w} * sizeof(Eigen::Vector3f); b += 64)
        __builtin_prefetch(next + b);
    }
    const bool above = r > 0;
    const bool any_inf = !above  ? RowBits<false, false>(cur, up, words, r2, m)
                         : eight ? RowBits<true, true>(cur, up, words, r2, m)
                                 : RowBits<true, false>(cur, up, words, r2, m);
    if (any_inf)
      return absl::InvalidArgumentError(
          absl::StrCat("link clustering: row ", r, " holds an infinite coordinate"));
    const int offsets[3] = {-1, 0, 1};  // north-west, north, north-east
    const bool use[3] = {eight && above, above, eight && above};
    for (uint32_t k = 0; k < words; ++k) {
      const uint64_t west_of_next = (m.west[k] >> 1) | (k + 1 < words ? m.west[k + 1] << 63 : 0);
      starts[k] = m.valid[k] & ~m.west[k];
      ends[k] = m.valid[k] & ~west_of_next;
    }
    std::vector<int32_t>& run_here = run_of[r & 1];
    const std::vector<int32_t>& run_above = run_of[(r + 1) & 1];
    for (uint32_t s = NextBit(starts, words, 0); s != kNone; s = NextBit(starts, words, s + 1)) {
      const uint32_t e = NextBit(ends, words, s);
      const auto id = static_cast<int32_t>(runs.size());
      runs.push_back({r, s, e, {0, 0, 0}, {0, 0, 0}});
      parent.push_back(id);
      RunBounds(cur, s, e, runs.back());
      std::fill(run_here.begin() + s, run_here.begin() + e + 1, id);
      for (int k = 0; k < 3; ++k) {
        if (!use[k]) continue;
        // All pixels up to the end of a run above (shifted by the offset)
        // reach that same run: merge once, then skip past it.
        for (uint32_t c = NextBit(vertical[k], words, s); c <= e;
             c = NextBit(vertical[k], words, c)) {
          const int32_t run_up = run_above[c + offsets[k]];
          Union(parent, id, run_up);
          const int64_t past = int64_t{runs[run_up].last_col} - offsets[k] + 1;
          c = static_cast<uint32_t>(std::max<int64_t>(c + 1, past));
          if (c >= w) break;
        }
      }
    }
  }

  // Pass 2: ids in raster order of each component's first run (parent[r] <=
  // r, so the entry r points to already holds its final id), statistics,
  // and labels written as spans.
  auto& clusters = result.clusters;
  clusters.clear();
  result.input_points = cloud.size();
  result.organized_path = true;
  result.labels.resize(cloud.size());
  int32_t* labels = result.labels.data();
  std::size_t cursor = 0;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const Run& run = runs[i];
    int32_t id;
    if (parent[i] == static_cast<int32_t>(i)) {
      id = static_cast<int32_t>(clusters.size());
      ClusterInfo k;
      k.min_row = k.max_row = run.row;
      k.min_col = run.first_col;
      k.max_col = run.last_col;
      k.min = run.min();
      k.max = run.max();
      clusters.push_back(k);
    } else {
      id = parent[parent[i]];
    }
    parent[i] = id;
    ClusterInfo& k = clusters[static_cast<std::size_t>(id)];
    k.size += run.last_col - run.first_col + 1;
    k.max_row = run.row;
    k.min_col = std::min(k.min_col, run.first_col);
    k.max_col = std::max(k.max_col, run.last_col);
    k.min = k.min.cwiseMin(run.min());
    k.max = k.max.cwiseMax(run.max());
    const std::size_t first = std::size_t{run.row} * w + run.first_col;
    const std::size_t last = std::size_t{run.row} * w + run.last_col;
    std::fill(labels + cursor, labels + first, kInvalid);
    std::fill(labels + first, labels + last + 1, id);
    cursor = last + 1;
  }
  std::fill(labels + cursor, labels + cloud.size(), kInvalid);

  // Pass 3: keep or remove each component; the mask as spans again.
  internal::DecideClusters(settings, result);
  result.kept_mask.assign(cloud.size(), 0);
  for (std::size_t i = 0; i < runs.size(); ++i)
    if (clusters[static_cast<std::size_t>(parent[i])].kept) {
      const std::size_t first = std::size_t{runs[i].row} * w + runs[i].first_col;
      std::memset(result.kept_mask.data() + first, 1, runs[i].last_col - runs[i].first_col + 1);
    }
  return absl::OkStatus();
}

}  // namespace surfinspect
