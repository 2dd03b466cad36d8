#include "core/filter/link_clustering_grid.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/filter/link_row_masks.h"
#include "core/filter/union_find.h"
#include "core/types/cancel.h"

namespace surfinspect {
namespace {

using link_row::kNone;
using link_row::NextBit;
using link_row::NextBitUpTo;
using link_row::RowMasks;
using link_row::RowSoA;

constexpr int32_t kInvalid = LinkClusteringResult::kInvalid;
// Rows per band: bands are labelled in parallel and joined at their seams,
// and their size does not depend on the thread count.
constexpr uint32_t kBandRows = 64;

// A maximal chain of west-linked valid pixels in one row, with its 3D bounds.
struct Run {
  uint32_t row, first_col, last_col;
  float lo[3], hi[3];
  Eigen::Map<const Eigen::Vector3f> min() const { return Eigen::Map<const Eigen::Vector3f>(lo); }
  Eigen::Map<const Eigen::Vector3f> max() const { return Eigen::Map<const Eigen::Vector3f>(hi); }
};

// Pass-1 state: two rows of structure-of-arrays and of run ids (this row
// and the one above), the link masks of the current row, and the runs with
// their union-find.
struct GridScratch {
  GridScratch(uint32_t width, uint32_t height)
      : words((width + 63) / 64),
        rows{RowSoA(64 * words), RowSoA(64 * words)},
        masks(7 * std::size_t{words}),
        run_of{std::vector<int32_t>(width), std::vector<int32_t>(width)} {
    // The demo scan has about 30 runs a row; the reserve avoids regrowing.
    runs.reserve(32 * std::size_t{height});
    forest.Reserve(32 * std::size_t{height});
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

// Merges run `id` (columns s..e of its row) with every run above that one
// of its pixels links to along the row's north-west, north and north-east
// masks. run_above[c] is the run of column c in the row above, an index
// into `above` and, plus `offset`, into the forest.
void MergeWithRunsAbove(const uint64_t* const vertical[3], int32_t id, uint32_t s, uint32_t e,
                        uint32_t width, bool eight, const int32_t* run_above, const Run* above,
                        int32_t offset, UnionFind& forest) {
  const int offsets[3] = {-1, 0, 1};  // north-west, north, north-east
  const bool use[3] = {eight, true, eight};
  for (int k = 0; k < 3; ++k) {
    if (!use[k]) continue;
    // All pixels up to the end of a run above (shifted by the offset)
    // reach that same run: merge once, then skip past it.
    for (uint32_t c = NextBitUpTo(vertical[k], s, e); c != kNone;
         c = NextBitUpTo(vertical[k], c, e)) {
      const int32_t run_up = run_above[c + offsets[k]];
      forest.Union(id, run_up + offset);
      const int64_t past = int64_t{above[run_up].last_col} - offsets[k] + 1;
      c = static_cast<uint32_t>(std::max<int64_t>(c + 1, past));
      if (c >= width) break;
    }
  }
}

// Pass 1 for row r: transposes it, computes its link masks, appends its runs
// and, unless r is its band's first row, merges them with the linked runs of
// the row above. A band's first row below another keeps its vertical masks
// for the join instead (`seam`, 3 * words).
absl::Status LabelRow(const PointCloud& cloud, uint32_t r, uint32_t band_first, float r2,
                      bool eight, GridScratch& g, std::vector<uint64_t>& seam) {
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
  const RowMasks m = g.m();
  const uint64_t* const vertical[3] = {m.north_west, m.north, m.north_east};
  const bool merge = above && r > band_first;
  if (above && !merge)
    for (int k = 0; k < 3; ++k) std::copy(vertical[k], vertical[k] + g.words, &seam[k * g.words]);
  link_row::RunBounds(m, g.words, g.starts(), g.ends());
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
    if (merge)
      MergeWithRunsAbove(vertical, id, s, e, w, eight, run_above.data(), g.runs.data(), 0,
                         g.forest);
  }
  return absl::OkStatus();
}

// Rows [first, end) labelled apart from the others: their runs, the
// union-find over them (band-local indices), the run of each column in the
// last row, and the first row's vertical masks and run count for the join.
struct Band {
  uint32_t first = 0, end = 0;
  std::vector<Run> runs;
  UnionFind forest;
  std::vector<int32_t> last_row_runs;
  std::vector<uint64_t> seam;
  std::size_t first_row_runs = 0;
  std::size_t offset = 0;  // of its first run among all, set by the join
  absl::Status status;
  // Pass 2: its components' count and first id, and its runs (band-local
  // indices) whose component starts in an earlier band.
  std::size_t roots = 0, first_id = 0;
  std::vector<uint32_t> foreign;
};

// Runs work(band) for every band, in parallel.
using EachBand = std::function<void(const std::function<void(Band&)>&)>;

void LabelBand(const PointCloud& cloud, float r2, bool eight, const std::atomic<bool>* cancel,
               Band& band) {
  GridScratch g(cloud.width, band.end - band.first);
  band.seam.assign(3 * std::size_t{g.words}, 0);
  // The row above the band, for the first row's vertical masks.
  if (band.first > 0)
    link_row::Transpose(&cloud.points[std::size_t{band.first - 1} * cloud.width], cloud.width,
                        g.rows[(band.first - 1) & 1]);
  for (uint32_t r = band.first; r < band.end; ++r) {
    if (IsCancelled(cancel)) {
      band.status = absl::CancelledError("link clustering: cancelled");
      return;
    }
    band.status = LabelRow(cloud, r, band.first, r2, eight, g, band.seam);
    if (!band.status.ok()) return;
    if (r == band.first) band.first_row_runs = g.runs.size();
  }
  band.runs = std::move(g.runs);
  band.forest = std::move(g.forest);
  band.last_row_runs = std::move(g.run_of[(band.end - 1) & 1]);
}

// Concatenates the bands' forests in row order and merges each band's
// first row with the last row of the band above. Union by smaller root
// keeps every root the lowest run of its component, so the result is the
// forest of one serial pass whatever the bands.
UnionFind JoinBands(std::vector<Band>& bands, uint32_t width, bool eight) {
  const uint32_t words = (width + 63) / 64;
  UnionFind forest;
  for (std::size_t b = 0; b < bands.size(); ++b) {
    Band& band = bands[b];
    band.offset = forest.size();
    forest.Append(band.forest);
    if (b == 0) continue;
    const uint64_t* const vertical[3] = {&band.seam[0], &band.seam[words],
                                         &band.seam[2 * std::size_t{words}]};
    const Band& above = bands[b - 1];
    for (std::size_t i = 0; i < band.first_row_runs; ++i)
      MergeWithRunsAbove(vertical, static_cast<int32_t>(band.offset + i), band.runs[i].first_col,
                         band.runs[i].last_col, width, eight, above.last_row_runs.data(),
                         above.runs.data(), static_cast<int32_t>(above.offset), forest);
  }
  return forest;
}

// Adds a run to its component's statistics; `first` when it is the
// component's first run (in raster order, as every fold is).
void Fold(const Run& run, bool first, ClusterInfo& k) {
  if (first) {
    k = ClusterInfo();
    k.min_row = k.max_row = run.row;
    k.min_col = run.first_col;
    k.max_col = run.last_col;
    k.min = run.min();
    k.max = run.max();
  }
  k.size += run.last_col - run.first_col + 1;
  k.max_row = run.row;
  k.min_col = std::min(k.min_col, run.first_col);
  k.max_col = std::max(k.max_col, run.last_col);
  k.min = k.min.cwiseMin(run.min());
  k.max = k.max.cwiseMax(run.max());
}

// Pass 2a, one band: its roots (parent[i] == i: a component's first run)
// numbered in raster order within the band.
void NumberRoots(Band& band, const std::vector<int32_t>& parent, std::vector<int32_t>& local_id) {
  band.roots = 0;
  for (std::size_t i = band.offset; i < band.offset + band.runs.size(); ++i)
    if (parent[i] == static_cast<int32_t>(i)) local_id[i] = static_cast<int32_t>(band.roots++);
}

// Pass 2b, one band: each run's component id (ids in raster order of each
// component's first run) and the statistics of the components that start
// in this band. A run whose component starts in an earlier band is kept in
// band.foreign, folded afterwards in band order: every component is then
// folded in raster order, as by one serial pass, and no two threads write
// the same component.
void NumberRuns(Band& band, const std::vector<Band>& bands, const std::vector<int32_t>& parent,
                const std::vector<int32_t>& local_id, std::vector<int32_t>& component,
                std::vector<ClusterInfo>& clusters) {
  band.foreign.clear();
  for (std::size_t j = 0; j < band.runs.size(); ++j) {
    const std::size_t i = band.offset + j;
    int32_t root = parent[i];
    while (parent[static_cast<std::size_t>(root)] != root) root = parent[root];
    const auto r = static_cast<std::size_t>(root);
    const bool here = r >= band.offset;
    const Band& owner =
        here ? band
             : *(std::upper_bound(bands.begin(), bands.end(), r,
                                  [](std::size_t run, const Band& b) { return run < b.offset; }) -
                 1);
    const int32_t id = static_cast<int32_t>(owner.first_id) + local_id[r];
    component[i] = id;
    if (here)
      Fold(band.runs[j], r == i, clusters[static_cast<std::size_t>(id)]);
    else
      band.foreign.push_back(static_cast<uint32_t>(j));
  }
}

// Pass 2: numbers the components and folds their statistics (2a, 2b, then
// the foreign runs of each band in band order). Returns each run's id.
std::vector<int32_t> NumberComponents(std::vector<Band>& bands, const std::vector<int32_t>& parent,
                                      const EachBand& each_band, LinkClusteringResult& result) {
  std::vector<int32_t> local_id(parent.size()), component(parent.size());
  each_band([&](Band& band) { NumberRoots(band, parent, local_id); });
  std::size_t total = 0;
  for (Band& band : bands) {
    band.first_id = total;
    total += band.roots;
  }
  result.clusters.resize(total);
  each_band(
      [&](Band& band) { NumberRuns(band, bands, parent, local_id, component, result.clusters); });
  for (const Band& band : bands)
    for (uint32_t j : band.foreign) {
      const auto id = static_cast<std::size_t>(component[band.offset + j]);
      Fold(band.runs[j], false, result.clusters[id]);
    }
  return component;
}

// Pass 3: one band's labels and kept mask, written as spans of its runs.
void WriteBand(const Band& band, const std::vector<int32_t>& component, uint32_t width,
               LinkClusteringResult& result) {
  int32_t* labels = result.labels.data();
  uint8_t* mask = result.kept_mask.data();
  std::size_t cursor = std::size_t{band.first} * width;
  for (std::size_t i = 0; i < band.runs.size(); ++i) {
    const Run& run = band.runs[i];
    const std::size_t first = std::size_t{run.row} * width + run.first_col;
    const std::size_t end = first + run.last_col - run.first_col + 1;
    const int32_t id = component[band.offset + i];
    std::fill(labels + cursor, labels + first, kInvalid);
    std::fill(labels + first, labels + end, id);
    std::memset(mask + cursor, 0, first - cursor);
    std::memset(mask + first, result.clusters[static_cast<std::size_t>(id)].kept, end - first);
    cursor = end;
  }
  const std::size_t band_end = std::size_t{band.end} * width;
  std::fill(labels + cursor, labels + band_end, kInvalid);
  std::memset(mask + cursor, 0, band_end - cursor);
}

}  // namespace

absl::Status ClusterLinksOrganized(const PointCloud& cloud, const LinkClusteringSettings& settings,
                                   LinkClusteringResult& result, const std::atomic<bool>* cancel) {
  if (auto st = internal::CheckInput(cloud, settings); !st.ok()) return st;
  const float r2 = LinkDistanceSquared(settings.link_distance_mm);
  const bool eight = settings.connectivity == 8;
  std::vector<Band> bands((cloud.height + kBandRows - 1) / kBandRows);
  for (std::size_t b = 0; b < bands.size(); ++b) {
    bands[b].first = static_cast<uint32_t>(b * kBandRows);
    bands[b].end = std::min(cloud.height, static_cast<uint32_t>((b + 1) * kBandRows));
  }
  const EachBand each_band = [&bands](const std::function<void(Band&)>& work) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, bands.size(), 1),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        for (std::size_t b = range.begin(); b != range.end(); ++b) work(bands[b]);
                      });
  };
  each_band([&](Band& band) { LabelBand(cloud, r2, eight, cancel, band); });
  // The first failing band in row order has the first failing row.
  for (const Band& band : bands)
    if (!band.status.ok()) return band.status;
  const std::vector<int32_t> parent = JoinBands(bands, cloud.width, eight).ReleaseParents();
  result.input_points = cloud.size();
  result.organized_path = true;
  result.labels.resize(cloud.size());
  result.kept_mask.resize(cloud.size());
  const std::vector<int32_t> component = NumberComponents(bands, parent, each_band, result);
  internal::DecideClusters(settings, result);
  each_band([&](Band& band) { WriteBand(band, component, cloud.width, result); });
  return absl::OkStatus();
}

}  // namespace surfinspect
