#include "core/filter/link_clustering_grid.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/filter/link_row_masks.h"
#include "core/filter/union_find.h"
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

// Pass-1 state: two rows of structure-of-arrays and of run ids (this row
// and the one above), the link masks of the current row, and the runs with
// their union-find.
struct GridScratch {
  GridScratch(uint32_t width, uint32_t height)
      : words((width + 63) / 64),
        rows{RowSoA(64 * words), RowSoA(64 * words)},
        masks(7 * std::size_t{words}),
        run_of{std::vector<int32_t>(width), std::vector<int32_t>(width)} {
    runs.reserve(4 * std::size_t{height});
    forest.Reserve(4 * std::size_t{height});
  }
  const uint32_t words;
  RowSoA rows[2];
  // Masks: valid, west, north-west, north, north-east, run starts, run ends.
  std::vector<uint64_t> masks;
  RowMasks m() {
    return {masks.data(), masks.data() + words, masks.data() + 2 * words, masks.data() + 3 * words,
            masks.data() + 4 * words};
  }
  uint64_t* starts() { return masks.data() + 5 * words; }
  uint64_t* ends() { return masks.data() + 6 * words; }
  std::vector<int32_t> run_of[2];
  std::vector<Run> runs;
  UnionFind forest;  // over run indices
};

// Run starts (valid, not west-linked) and ends (valid, next pixel not
// west-linked) of the current row, from its masks.
void FindRunBounds(GridScratch& g) {
  const RowMasks m = g.m();
  uint64_t* starts = g.starts();
  uint64_t* ends = g.ends();
  for (uint32_t k = 0; k < g.words; ++k) {
    const uint64_t west_of_next = (m.west[k] >> 1) | (k + 1 < g.words ? m.west[k + 1] << 63 : 0);
    starts[k] = m.valid[k] & ~m.west[k];
    ends[k] = m.valid[k] & ~west_of_next;
  }
}

// Merges run `id` (columns s..e of this row) with every run above that one
// of its pixels links to along the masks' north-west, north and north-east.
void MergeWithRunsAbove(GridScratch& g, int32_t id, uint32_t s, uint32_t e, uint32_t width,
                        bool eight, const std::vector<int32_t>& run_above) {
  const RowMasks m = g.m();
  const uint64_t* const vertical[3] = {m.north_west, m.north, m.north_east};
  const int offsets[3] = {-1, 0, 1};  // north-west, north, north-east
  const bool use[3] = {eight, true, eight};
  for (int k = 0; k < 3; ++k) {
    if (!use[k]) continue;
    // All pixels up to the end of a run above (shifted by the offset)
    // reach that same run: merge once, then skip past it.
    for (uint32_t c = NextBit(vertical[k], g.words, s); c <= e;
         c = NextBit(vertical[k], g.words, c)) {
      const int32_t run_up = run_above[c + offsets[k]];
      g.forest.Union(id, run_up);
      const int64_t past = int64_t{g.runs[run_up].last_col} - offsets[k] + 1;
      c = static_cast<uint32_t>(std::max<int64_t>(c + 1, past));
      if (c >= width) break;
    }
  }
}

// Pass 1 for row r: transposes it, computes its link masks, appends its runs
// and merges them with the linked runs of the row above.
absl::Status LabelRow(const PointCloud& cloud, uint32_t r, float r2, bool eight, GridScratch& g) {
  const uint32_t w = cloud.width, h = cloud.height;
  RowSoA& cur = g.rows[r & 1];
  const RowSoA& up = g.rows[(r + 1) & 1];
  link_row::Transpose(&cloud.points[std::size_t{r} * w], w, cur);
  if (r + 1 < h) {
    // The next row streams in while this one is labelled: the transpose
    // is otherwise bound by load latency, not bandwidth (measured).
    const char* next = reinterpret_cast<const char*>(&cloud.points[std::size_t{r + 1} * w]);
    for (std::size_t b = 0; b < std::size_t{w} * sizeof(Eigen::Vector3f); b += 64)
      __builtin_prefetch(next + b);
  }
  const bool above = r > 0;
  if (link_row::ComputeMasks(cur, above ? &up : nullptr, eight, g.words, r2, g.m()))
    return absl::InvalidArgumentError(
        absl::StrCat("link clustering: row ", r, " holds an infinite coordinate"));
  FindRunBounds(g);
  const uint64_t* starts = g.starts();
  const uint64_t* ends = g.ends();
  std::vector<int32_t>& run_here = g.run_of[r & 1];
  const std::vector<int32_t>& run_above = g.run_of[(r + 1) & 1];
  for (uint32_t s = NextBit(starts, g.words, 0); s != kNone; s = NextBit(starts, g.words, s + 1)) {
    const uint32_t e = NextBit(ends, g.words, s);
    const int32_t id = g.forest.Add();
    g.runs.push_back({r, s, e, {0, 0, 0}, {0, 0, 0}});
    link_row::Bounds(cur, s, e, g.runs.back().lo, g.runs.back().hi);
    std::fill(run_here.begin() + s, run_here.begin() + e + 1, id);
    if (above) MergeWithRunsAbove(g, id, s, e, w, eight, run_above);
  }
  return absl::OkStatus();
}

// Pass 2: ids in raster order of each component's first run (parent[r] <=
// r, so the entry r points to already holds its final id), statistics, and
// labels written as spans. On return parent[i] is run i's component id.
void NumberComponents(const std::vector<Run>& runs, std::vector<int32_t>& parent, uint32_t width,
                      LinkClusteringResult& result) {
  auto& clusters = result.clusters;
  clusters.clear();
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
    const std::size_t first = std::size_t{run.row} * width + run.first_col;
    const std::size_t last = std::size_t{run.row} * width + run.last_col;
    std::fill(labels + cursor, labels + first, kInvalid);
    std::fill(labels + first, labels + last + 1, id);
    cursor = last + 1;
  }
  std::fill(labels + cursor, labels + result.labels.size(), kInvalid);
}

// Pass 3: the kept mask, written as spans of the kept runs.
void FillKeptMask(const std::vector<Run>& runs, const std::vector<int32_t>& component,
                  uint32_t width, LinkClusteringResult& result) {
  result.kept_mask.assign(result.labels.size(), 0);
  for (std::size_t i = 0; i < runs.size(); ++i)
    if (result.clusters[static_cast<std::size_t>(component[i])].kept) {
      const std::size_t first = std::size_t{runs[i].row} * width + runs[i].first_col;
      std::memset(result.kept_mask.data() + first, 1, runs[i].last_col - runs[i].first_col + 1);
    }
}

}  // namespace

absl::Status ClusterLinksOrganized(const PointCloud& cloud, const LinkClusteringSettings& settings,
                                   LinkClusteringResult& result, const std::atomic<bool>* cancel) {
  if (auto st = internal::CheckInput(cloud, settings); !st.ok()) return st;
  const float r2 = LinkDistanceSquared(settings.link_distance_mm);
  const bool eight = settings.connectivity == 8;
  GridScratch g(cloud.width, cloud.height);
  for (uint32_t r = 0; r < cloud.height; ++r) {
    if (IsCancelled(cancel)) return absl::CancelledError("link clustering: cancelled");
    if (auto st = LabelRow(cloud, r, r2, eight, g); !st.ok()) return st;
  }
  result.input_points = cloud.size();
  result.organized_path = true;
  result.labels.resize(cloud.size());
  std::vector<int32_t> component = std::move(g.forest).ReleaseParents();
  NumberComponents(g.runs, component, cloud.width, result);
  internal::DecideClusters(settings, result);
  FillKeptMask(g.runs, component, cloud.width, result);
  return absl::OkStatus();
}

}  // namespace surfinspect
