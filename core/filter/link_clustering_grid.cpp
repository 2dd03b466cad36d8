#include "core/filter/link_clustering_grid.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <vector>

#include "core/filter/grid_bands.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

using grid::Band;
using grid::kBandRows;
using grid::Run;

constexpr int32_t kInvalid = LinkClusteringResult::kInvalid;

// Runs work(band) for every band, in parallel.
using EachBand = std::function<void(const std::function<void(Band&)>&)>;

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

// Pass 2, one band: each run's component id and the statistics of the
// components that begin in this band. Ids are in raster order of each
// component's first run, its root (parent[i] == i), and the band's ids
// begin at band.first_id. A run whose component begins in an earlier band
// goes to band.foreign with its root, for NumberComponents to fold
// afterwards in band order: every component then folds in raster order, as
// in one serial pass, and no two threads write the same component.
void NumberRuns(Band& band, const std::vector<int32_t>& parent, std::vector<int32_t>& component,
                std::vector<ClusterInfo>& clusters) {
  band.foreign.clear();
  auto next = static_cast<int32_t>(band.first_id);
  for (std::size_t j = 0; j < band.runs.size(); ++j) {
    const std::size_t i = band.offset + j;
    int32_t root = parent[i];
    while (parent[static_cast<std::size_t>(root)] != root) root = parent[root];
    const auto r = static_cast<std::size_t>(root);
    if (r < band.offset) {
      band.foreign.push_back({static_cast<uint32_t>(j), root});
      continue;
    }
    // The root is its component's first run: its id is set before any other
    // run of the component asks for it.
    const int32_t id = r == i ? next++ : component[r];
    component[i] = id;
    Fold(band.runs[j], r == i, clusters[static_cast<std::size_t>(id)]);
  }
}

// Pass 2: numbers the components and folds their statistics. Returns each
// run's component id.
std::vector<int32_t> NumberComponents(std::vector<Band>& bands, const std::vector<int32_t>& parent,
                                      const EachBand& each_band, LinkClusteringResult& result) {
  std::size_t total = 0;
  for (Band& band : bands) {
    band.first_id = total;
    for (std::size_t i = band.offset; i < band.offset + band.runs.size(); ++i)
      total += parent[i] == static_cast<int32_t>(i);
  }
  std::vector<int32_t> component(parent.size());
  result.clusters.resize(total);
  each_band([&](Band& band) { NumberRuns(band, parent, component, result.clusters); });
  for (const Band& band : bands)
    for (const auto& [j, root] : band.foreign) {
      const int32_t id = component[static_cast<std::size_t>(root)];
      component[band.offset + j] = id;
      Fold(band.runs[j], false, result.clusters[static_cast<std::size_t>(id)]);
    }
  return component;
}

// Pass 3: one band's labels and kept mask. The band (256 KB of labels and
// 64 KB of mask for 1024 columns, inside a core's L2) is first set to "no
// data" by two block writes, then its runs are written over it: most of a
// scan's runs are single pixels, stored directly, where per-gap and per-run
// library calls cost more than the bytes (bench/link_clustering_bench.cpp's
// grid rows show the gain over a per-gap writer).
void WriteBand(const Band& band, const std::vector<int32_t>& component, uint32_t width,
               LinkClusteringResult& result) {
  const std::size_t band_first = std::size_t{band.first} * width;
  const std::size_t band_end = std::size_t{band.end} * width;
  int32_t* labels = result.labels.data();
  uint8_t* mask = result.kept_mask.data();
  std::fill(labels + band_first, labels + band_end, kInvalid);
  std::memset(mask + band_first, 0, band_end - band_first);
  for (std::size_t i = 0; i < band.runs.size(); ++i) {
    const Run& run = band.runs[i];
    const std::size_t first = std::size_t{run.row} * width + run.first_col;
    const int32_t id = component[band.offset + i];
    const uint8_t kept = result.clusters[static_cast<std::size_t>(id)].kept;
    if (run.first_col == run.last_col) {
      labels[first] = id, mask[first] = kept;
      continue;
    }
    const std::size_t end = first + run.last_col - run.first_col + 1;
    std::fill(labels + first, labels + end, id);
    if (kept) std::memset(mask + first, kept, end - first);
  }
}

}  // namespace

absl::Status ClusterLinksOrganized(const PointCloud& cloud, const LinkClusteringSettings& settings,
                                   LinkClusteringResult& result, const std::atomic<bool>* cancel) {
  RETURN_IF_ERROR(internal::CheckInput(cloud, settings));
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
  each_band([&](Band& band) { grid::LabelBand(cloud, r2, eight, cancel, band); });
  // The first failing band in row order has the first failing row.
  for (const Band& band : bands)
    if (!band.status.ok()) return band.status;
  const std::vector<int32_t> parent = grid::JoinBands(bands, cloud.width, eight).ReleaseParents();
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
