#include "core/filter/link_clustering_grid.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/filter/link_row_masks.h"
#include "core/types/cancel.h"

namespace surfinspect {
namespace {

using link_row::RowMasks;
using link_row::RowSoA;

constexpr int32_t kInvalid = LinkClusteringResult::kInvalid;
constexpr uint32_t kNone = UINT32_MAX;

// A maximal chain of west-linked valid pixels in one row, with its 3D bounds.
struct Run {
  uint32_t row, first_col, last_col;
  float lo[3], hi[3];
  Eigen::Map<const Eigen::Vector3f> min() const { return Eigen::Map<const Eigen::Vector3f>(lo); }
  Eigen::Map<const Eigen::Vector3f> max() const { return Eigen::Map<const Eigen::Vector3f>(hi); }
};

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
  if (a < b)
    parent[b] = a;
  else if (b < a)
    parent[a] = b;
}

}  // namespace

absl::Status ClusterLinksOrganized(const PointCloud& cloud, const LinkClusteringSettings& settings,
                                   LinkClusteringResult& result, const std::atomic<bool>* cancel) {
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
    if (IsCancelled(cancel)) return absl::CancelledError("link clustering: cancelled");
    RowSoA& cur = rows[r & 1];
    const RowSoA& up = rows[(r + 1) & 1];
    link_row::Transpose(&cloud.points[std::size_t{r} * w], w, cur);
    if (r + 1 < h) {
      // The next row streams in while this one is labelled: the transpose
      // is otherwise bound by load latency, not bandwidth (measured).
      const char* next = reinterpret_cast<const char*>(&cloud.points[std::size_t{r + 1} * w]);
      for (std::size_t b = 0; b < std::size_t{w} * sizeof(Eigen::Vector3f); b += 64)
        __builtin_prefetch(next + b);
    }
    const bool above = r > 0;
    const bool any_inf = link_row::ComputeMasks(cur, above ? &up : nullptr, eight, words, r2, m);
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
      link_row::Bounds(cur, s, e, runs.back().lo, runs.back().hi);
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
