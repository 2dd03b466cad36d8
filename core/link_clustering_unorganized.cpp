#include "core/link_clustering_unorganized.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"

namespace surfinspect {
namespace {

constexpr int32_t kInvalid = LinkClusteringResult::kInvalid;
constexpr int kMaxAxisBits = 21;  // 3 x 21 bits fit one uint64 key

// Bits needed to hold values 0..v.
int BitsFor(uint64_t v) {
  int b = 1;
  while (b < 64 && (v >> b) != 0) ++b;
  return b;
}

// LSD radix sort of (key, value) pairs by the low `key_bits` bits of key,
// 11-bit digits: O(n) per pass, and a 300 mm part at 0.5 mm cells needs
// only 2-3 passes. `keys`/`values` hold the sorted result on return.
void RadixSort(std::vector<uint64_t>& keys, std::vector<uint32_t>& values, int key_bits) {
  constexpr int kDigitBits = 11;
  constexpr std::size_t kBuckets = std::size_t{1} << kDigitBits;
  std::vector<uint64_t> keys_tmp(keys.size());
  std::vector<uint32_t> values_tmp(values.size());
  std::vector<std::size_t> start(kBuckets);
  for (int shift = 0; shift < key_bits; shift += kDigitBits) {
    std::fill(start.begin(), start.end(), 0);
    for (uint64_t k : keys) ++start[(k >> shift) & (kBuckets - 1)];
    std::size_t sum = 0;
    for (auto& s : start) sum += std::exchange(s, sum);
    for (std::size_t i = 0; i < keys.size(); ++i) {
      const std::size_t to = start[(keys[i] >> shift) & (kBuckets - 1)]++;
      keys_tmp[to] = keys[i];
      values_tmp[to] = values[i];
    }
    keys.swap(keys_tmp);
    values.swap(values_tmp);
  }
}

// Union-find over sorted positions; path halving, union by smaller index.
struct Forest {
  std::vector<int32_t> parent;
  int32_t Find(int32_t i) {
    while (parent[i] != i) {
      parent[i] = parent[parent[i]];
      i = parent[i];
    }
    return i;
  }
};

// The sorted points as structure-of-arrays, for cache-friendly pair tests.
struct SortedPoints {
  std::vector<float> x, y, z;
  std::vector<uint64_t> key;
};

// Tests point a against the sorted positions [b0, b1) and merges the links.
void LinkRange(const SortedPoints& s, int32_t a, std::size_t b0, std::size_t b1, float r2,
               Forest& forest) {
  const Eigen::Vector3f pa(s.x[a], s.y[a], s.z[a]);
  int32_t ra = forest.Find(a);
  for (std::size_t b = b0; b < b1; ++b) {
    if (!PointsLinked(pa, Eigen::Vector3f(s.x[b], s.y[b], s.z[b]), r2)) continue;
    const int32_t rb = forest.Find(static_cast<int32_t>(b));
    if (rb == ra) continue;
    if (ra < rb) {
      forest.parent[rb] = ra;
    } else {
      forest.parent[ra] = rb;
      ra = rb;
    }
  }
}

}  // namespace

absl::Status ClusterLinksUnorganized(const PointCloud& cloud,
                                     const LinkClusteringSettings& settings,
                                     LinkClusteringResult& result,
                                     const std::atomic<bool>* cancel) {
  if (auto st = internal::CheckInput(cloud, settings); !st.ok()) return st;
  auto cancelled = [&] { return cancel && cancel->load(std::memory_order_relaxed); };
  const std::size_t n = cloud.size();
  result.input_points = n;
  result.organized_path = false;
  result.clusters.clear();
  result.labels.assign(n, kInvalid);

  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  std::size_t m = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    if (PointCloud::IsValid(p)) {
      lo = lo.cwiseMin(p.cast<double>());
      hi = hi.cwiseMax(p.cast<double>());
      ++m;
    } else if (p.array().isInf().any()) {
      return absl::InvalidArgumentError(
          absl::StrCat("link clustering: point ", i, " has an infinite coordinate"));
    }
  }
  // The cell is a hair larger than the link distance so float rounding in
  // PointsLinked can never link two points whose cells are 2 apart.
  const double cell = settings.link_distance_mm * (1.0 + 1e-5);
  int bits[3] = {0, 0, 0};
  for (int a = 0; m > 0 && a < 3; ++a) {
    // Cell coordinates start at 1 so that x-1 and y-1 never borrow across
    // key fields, and stop 1 below the field's top so that x+1 fits.
    const double cells = std::floor((hi[a] - lo[a]) / cell) + 3.0;
    if (!(cells < static_cast<double>(uint64_t{1} << kMaxAxisBits)))
      return absl::InvalidArgumentError(absl::StrCat(
          "link clustering: the cloud spans ", hi[a] - lo[a], " mm on axis ", a,
          ", more than 2^21 link distances of ", settings.link_distance_mm, " mm"));
    bits[a] = BitsFor(static_cast<uint64_t>(cells) - 1);
  }

  std::vector<uint64_t> keys;
  std::vector<uint32_t> order;  // sorted position -> point index
  keys.reserve(m);
  order.reserve(m);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    if (!PointCloud::IsValid(p)) continue;
    uint64_t c[3];
    for (int a = 0; a < 3; ++a)
      c[a] = static_cast<uint64_t>(std::floor((p[a] - lo[a]) / cell)) + 1;
    keys.push_back(c[0] | (c[1] << bits[0]) | (c[2] << (bits[0] + bits[1])));
    order.push_back(static_cast<uint32_t>(i));
  }
  if (cancelled()) return absl::CancelledError("link clustering: cancelled");
  RadixSort(keys, order, bits[0] + bits[1] + bits[2]);

  SortedPoints s;
  s.x.resize(m);
  s.y.resize(m);
  s.z.resize(m);
  for (std::size_t k = 0; k < m; ++k) {
    const Eigen::Vector3f& p = cloud.points[order[k]];
    s.x[k] = p.x();
    s.y[k] = p.y();
    s.z[k] = p.z();
  }
  s.key = std::move(keys);

  Forest forest;
  forest.parent.resize(m);
  std::iota(forest.parent.begin(), forest.parent.end(), 0);
  const float r2 = LinkDistanceSquared(settings.link_distance_mm);
  const uint64_t step_y = uint64_t{1} << bits[0];
  const uint64_t step_z = uint64_t{1} << (bits[0] + bits[1]);
  // Rows (dy, dz) of forward neighbours whose x-1..x+1 cells are one run.
  const uint64_t row_offset[4] = {step_y, step_z - step_y, step_z, step_z + step_y};
  std::size_t row_begin[4] = {0, 0, 0, 0}, row_end[4] = {0, 0, 0, 0};
  std::size_t same_row_end = 0;
  auto advance = [&](std::size_t& cursor, uint64_t first_key_not_before) {
    while (cursor < m && s.key[cursor] < first_key_not_before) ++cursor;
  };
  std::size_t cells_done = 0;
  for (std::size_t begin = 0; begin < m;) {
    if ((++cells_done & 4095) == 0 && cancelled())
      return absl::CancelledError("link clustering: cancelled");
    const uint64_t key = s.key[begin];
    std::size_t end = begin;
    while (end < m && s.key[end] == key) ++end;
    advance(same_row_end, key + 2);  // this cell and x+1
    for (int k = 0; k < 4; ++k) {
      advance(row_begin[k], key + row_offset[k] - 1);
      advance(row_end[k], key + row_offset[k] + 2);
    }
    for (std::size_t a = begin; a < end; ++a) {
      const auto ai = static_cast<int32_t>(a);
      LinkRange(s, ai, a + 1, same_row_end, r2, forest);
      for (int k = 0; k < 4; ++k) LinkRange(s, ai, row_begin[k], row_end[k], r2, forest);
    }
    begin = end;
  }

  // Ids in order of each component's first point index, with statistics.
  std::vector<int32_t> position_of(n, kInvalid);
  for (std::size_t k = 0; k < m; ++k) position_of[order[k]] = static_cast<int32_t>(k);
  std::vector<int32_t> id_of_root(m, kInvalid);
  for (std::size_t i = 0; i < n; ++i) {
    if (position_of[i] == kInvalid) continue;
    const int32_t root = forest.Find(position_of[i]);
    int32_t& id = id_of_root[root];
    const Eigen::Vector3f& p = cloud.points[i];
    const auto col = static_cast<uint32_t>(i);
    if (id == kInvalid) {
      id = static_cast<int32_t>(result.clusters.size());
      ClusterInfo k;
      k.min_col = col;
      k.min = k.max = p;
      result.clusters.push_back(k);
    }
    ClusterInfo& k = result.clusters[static_cast<std::size_t>(id)];
    ++k.size;
    k.max_col = col;
    k.min = k.min.cwiseMin(p);
    k.max = k.max.cwiseMax(p);
    result.labels[i] = id;
  }
  internal::DecideClusters(settings, result);
  internal::FillKeptMaskFromLabels(result);
  return absl::OkStatus();
}

}  // namespace surfinspect
