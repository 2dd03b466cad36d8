// Pass 1 of the grid link clustering (link_clustering_grid.h): bands of
// rows labelled as runs apart from each other, in parallel, then joined at
// their seams into one union-find over all runs.
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "core/types/point_cloud.h"
#include "core/types/union_find.h"

namespace surfinspect::grid {

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

// Rows [first, end) labelled apart from the others: their runs, the
// union-find over them (band-local indices), where the last row's runs
// begin, and the first row's vertical masks and run count for the join.
struct Band {
  uint32_t first = 0, end = 0;
  std::vector<Run> runs;
  UnionFind forest;
  std::size_t last_row_first = 0;  // index of the last row's first run
  std::vector<uint64_t> seam;
  std::size_t first_row_runs = 0;
  std::size_t offset = 0;  // of its first run among all, set by the join
  absl::Status status;
  // Set by the numbering pass (link_clustering_grid.cpp): its first
  // component id, and its runs (band-local index, root) whose component
  // begins in an earlier band.
  std::size_t first_id = 0;
  struct Foreign {
    uint32_t run;
    int32_t root;
  };
  std::vector<Foreign> foreign;
};

// Labels rows [band.first, band.end) of `cloud` with squared link distance
// r2 and 8 neighbours (`eight`) or 4: fills the band's runs, forest, last
// row and seam, or band.status (InvalidArgument on an infinite coordinate,
// Cancelled).
void LabelBand(const PointCloud& cloud, float r2, bool eight, const std::atomic<bool>* cancel,
               Band& band);

// Concatenates the bands' forests in row order and merges each band's
// first row with the last row of the band above; sets each band's offset.
// Union by smaller root keeps every root the lowest run of its component,
// so the result is the forest of one serial pass whatever the bands.
UnionFind JoinBands(std::vector<Band>& bands, uint32_t width, bool eight);

}  // namespace surfinspect::grid
