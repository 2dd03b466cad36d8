// Link clustering for unorganized clouds (the general path; see
// link_clustering.h for the semantics): every pair of points within the link
// distance is linked, whatever the storage order or grid.
//
// Method: a voxel grid, as in grid-based DBSCAN (Gunawan, "A faster
// algorithm for DBSCAN", 2013), with cells of edge d / sqrt(3) for the link
// distance d, so that all points of one cell are linked to each other and
// the cell, not the point, is the union-find element. Linked points then lie
// at most 2 cells apart per axis. For each pair of non-empty neighbouring
// cells not yet in one component, the pairs of their points are tested
// until one links. Instead of a hash table the points are radix-sorted by
// packed cell key (z, y, x major to minor): the cells x-2..x+2 of one
// (y, z) row are then one contiguous range of the sorted cells, found by
// cursors that only move forward. (A grid with cells of edge d needs only
// 27 neighbours but must test every pair of points, far slower on dense
// scans.)
#pragma once

#include <atomic>

#include "absl/status/status.h"
#include "core/filter/link_clustering.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

// Treats `cloud` as a plain list of points (any grid is ignored). Fails with
// InvalidArgument on bad settings, an empty cloud, an infinite coordinate,
// or when the cloud spans 2^21 - 5 or more cells on an axis (a link
// distance absurdly small for the cloud); Cancelled when `cancel` is set.
absl::Status ClusterLinksUnorganized(const PointCloud& cloud,
                                     const LinkClusteringSettings& settings,
                                     LinkClusteringResult& result,
                                     const std::atomic<bool>* cancel = nullptr);

}  // namespace surfinspect
