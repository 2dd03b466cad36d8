#include "core/filter/link_clustering_unorganized.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/types/cancel.h"

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

// Union-find over cells; path halving, the smaller index becomes the root.
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

// The valid points sorted by cell, as structure-of-arrays, and the cells.
struct SortedCells {
  std::vector<float> x, y, z;     // per sorted position
  std::vector<uint64_t> key;      // per cell, ascending
  std::vector<uint32_t> begin;    // per cell: first sorted position; + end sentinel
  std::vector<uint32_t> cell_of;  // per sorted position
};

// Whether some point of cell a links to some point of cell b (the first
// link found ends the search: one link merges the two cells).
bool AnyLinked(const SortedCells& s, uint32_t a, uint32_t b, float r2) {
  for (uint32_t i = s.begin[a]; i < s.begin[a + 1]; ++i) {
    const Eigen::Vector3f p(s.x[i], s.y[i], s.z[i]);
    for (uint32_t j = s.begin[b]; j < s.begin[b + 1]; ++j)
      if (PointsLinked(p, Eigen::Vector3f(s.x[j], s.y[j], s.z[j]), r2)) return true;
  }
  return false;
}

}  // namespace

absl::Status ClusterLinksUnorganized(const PointCloud& cloud,
                                     const LinkClusteringSettings& settings,
                                     LinkClusteringResult& result,
                                     const std::atomic<bool>* cancel) {
  if (auto st = internal::CheckInput(cloud, settings); !st.ok()) return st;
  auto cancelled = [&] { return IsCancelled(cancel); };
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
  // Cells of edge d / sqrt(3), shrunk by 1e-4 so that float rounding in
  // PointsLinked can never fail to link two points of the same cell (their
  // true distance is < 0.9999 d; the float error is ~1e-7 relative).
  const double cell = settings.link_distance_mm / std::sqrt(3.0) * (1.0 - 1e-4);
  int bits[3] = {0, 0, 0};
  for (int a = 0; m > 0 && a < 3; ++a) {
    // Cell coordinates start at 2 so that x-2 and y-2 never borrow across
    // key fields, and stop 2 below the field's top so that x+2 fits.
    const double cells = std::floor((hi[a] - lo[a]) / cell) + 5.0;
    if (!(cells < static_cast<double>(uint64_t{1} << kMaxAxisBits)))
      return absl::InvalidArgumentError(absl::StrCat(
          "link clustering: the cloud spans ", hi[a] - lo[a], " mm on axis ", a,
          ", more than 2^21 cells for a link distance of ", settings.link_distance_mm, " mm"));
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
    for (int a = 0; a < 3; ++a) c[a] = static_cast<uint64_t>(std::floor((p[a] - lo[a]) / cell)) + 2;
    keys.push_back(c[0] | (c[1] << bits[0]) | (c[2] << (bits[0] + bits[1])));
    order.push_back(static_cast<uint32_t>(i));
  }
  if (cancelled()) return absl::CancelledError("link clustering: cancelled");
  RadixSort(keys, order, bits[0] + bits[1] + bits[2]);

  SortedCells s;
  s.x.resize(m);
  s.y.resize(m);
  s.z.resize(m);
  s.cell_of.resize(m);
  for (std::size_t k = 0; k < m; ++k) {
    // A gather in cell order: random reads of an unorganized cloud, so the
    // point needed 16 steps later is requested now.
    if (k + 16 < m) __builtin_prefetch(&cloud.points[order[k + 16]]);
    const Eigen::Vector3f& p = cloud.points[order[k]];
    s.x[k] = p.x();
    s.y[k] = p.y();
    s.z[k] = p.z();
    if (k == 0 || keys[k] != keys[k - 1]) {
      s.key.push_back(keys[k]);
      s.begin.push_back(static_cast<uint32_t>(k));
    }
    s.cell_of[k] = static_cast<uint32_t>(s.key.size() - 1);
  }
  const auto num_cells = static_cast<uint32_t>(s.key.size());
  s.begin.push_back(static_cast<uint32_t>(m));

  Forest forest;
  forest.parent.resize(num_cells);
  std::iota(forest.parent.begin(), forest.parent.end(), 0);
  const float r2 = LinkDistanceSquared(settings.link_distance_mm);
  const uint64_t step_y = uint64_t{1} << bits[0];
  const uint64_t step_z = uint64_t{1} << (bits[0] + bits[1]);
  // Forward neighbour rows (dy, dz) whose cells x-2..x+2 are one key range:
  // dz = 0 with dy = 1, 2, and dz = 1, 2 with dy = -2..2. The cells x+1 and
  // x+2 of the cell's own row follow it directly in the sorted order.
  uint64_t row_offset[12];
  int rows = 0;
  for (int dz = 0; dz <= 2; ++dz)
    for (int dy = dz == 0 ? 1 : -2; dy <= 2; ++dy)
      row_offset[rows++] = dz * step_z + dy * step_y;  // wraps only for dy < 0, dz > 0
  uint32_t row_first[12] = {};
  auto advance = [&](uint32_t& cursor, uint64_t first_key_not_before) {
    while (cursor < num_cells && s.key[cursor] < first_key_not_before) ++cursor;
  };
  for (uint32_t a = 0; a < num_cells; ++a) {
    if ((a & 4095) == 0 && cancelled()) return absl::CancelledError("link clustering: cancelled");
    const uint64_t key = s.key[a];
    int32_t root_a = forest.Find(static_cast<int32_t>(a));
    auto try_link = [&](uint32_t b) {
      const int32_t root_b = forest.Find(static_cast<int32_t>(b));
      if (root_b == root_a || !AnyLinked(s, a, b, r2)) return;
      if (root_a < root_b) {
        forest.parent[root_b] = root_a;
      } else {
        forest.parent[root_a] = root_b;
        root_a = root_b;
      }
    };
    for (uint32_t b = a + 1; b < num_cells && s.key[b] <= key + 2; ++b) try_link(b);
    for (int k = 0; k < rows; ++k) {
      const uint64_t first_key = key + row_offset[k] - 2, last_key = first_key + 4;
      advance(row_first[k], first_key);
      for (uint32_t b = row_first[k]; b < num_cells && s.key[b] <= last_key; ++b) try_link(b);
    }
  }

  // Each point's root cell, found in cell order (local) and scattered to
  // the point's index; then ids in order of each component's first point
  // index, with statistics.
  for (std::size_t k = 0; k < m; ++k)
    result.labels[order[k]] = forest.Find(static_cast<int32_t>(s.cell_of[k]));
  std::vector<int32_t> id_of_root(num_cells, kInvalid);
  for (std::size_t i = 0; i < n; ++i) {
    if (result.labels[i] == kInvalid) continue;
    int32_t& id = id_of_root[result.labels[i]];
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
