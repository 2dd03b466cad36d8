// Link clustering for unorganized clouds (the general path; see
// link_clustering.h for the semantics): every pair of points within the link
// distance is linked, whatever the storage order or grid.
//
// Method: a voxel grid whose cell edge equals the link distance, so linked
// points lie in the same or one of the 26 neighbouring cells. Instead of a
// hash table the points are radix-sorted by packed cell key (z, y, x major
// to minor); the three cells x-1..x+1 of one (y, z) row are then one
// contiguous run of the sorted order, and the 13 "forward" neighbours of a
// cell are 4 such runs plus the cell x+1, whose start positions grow with
// the cell key, so monotone cursors find them without any search. Each
// candidate pair is tested with PointsLinked and merged in a union-find.
#pragma once

#include <atomic>

#include "absl/status/status.h"
#include "core/link_clustering.h"
#include "core/point_cloud.h"

namespace surfinspect {

// Treats `cloud` as a plain list of points (any grid is ignored). Fails with
// InvalidArgument on bad settings, an empty cloud, an infinite coordinate,
// or when the cloud's extent spans 2^21 - 3 or more cells on an axis (a link
// distance absurdly small for the cloud); Cancelled when `cancel` is set.
absl::Status ClusterLinksUnorganized(const PointCloud& cloud,
                                     const LinkClusteringSettings& settings,
                                     LinkClusteringResult& result,
                                     const std::atomic<bool>* cancel = nullptr);

}  // namespace surfinspect
