// Link clustering on an organized grid (the fast path for sensor data; see
// link_clustering.h for the semantics): only the 4 or 8 grid neighbours of a
// pixel may link to it.
//
// Method: a run-based two-pass labelling (He, Chao & Suzuki, "A run-based
// two-scan labeling algorithm", IEEE TIP 2008) with 3D-distance links. Each
// row is transposed to structure-of-arrays and its link tests (west,
// north-west, north, north-east) become 64-bit masks, 4 pixels per SSE2
// instruction (8 with AVX2 and 16 with AVX-512 where the CPU has them; with
// AVX-512 in the same loop as the transpose). A run is a maximal chain
// of west-linked pixels; runs are the union-find elements, and a run's
// north-west, north and north-east links become one mask of the columns
// above it links to, visited once per touching run above (bit scans skip
// the rest; a cursor walks the runs above), so the per-pixel work is a
// handful of vector instructions. Bands of 64 rows are labelled
// in parallel and joined where each band's first row meets the row above
// it; the union makes the smaller run the root, so the forest is the serial
// pass's (grid_bands.h). The second pass numbers the components in raster
// order of their first runs: the roots are counted per band after the
// join, then each band, in parallel, gives each run its component's id and
// folds the run into the statistics of the components that begin in the
// band; runs of components begun in an earlier band are folded afterwards,
// in band order, so every fold is in raster order. The third writes labels
// and the kept mask as filled spans, band by band in parallel. No
// per-point heap allocation; scratch is O(width + runs).
#pragma once

#include <atomic>

#include "absl/status/status.h"
#include "core/filter/link_clustering.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

// Grid path on an organized cloud (height == 1 is accepted as one row).
// Errors as ClusterLinks. Runs on the calling TBB arena's threads; the
// result does not depend on their number.
absl::Status ClusterLinksOrganized(const PointCloud& cloud, const LinkClusteringSettings& settings,
                                   LinkClusteringResult& result,
                                   const std::atomic<bool>* cancel = nullptr);

}  // namespace surfinspect
