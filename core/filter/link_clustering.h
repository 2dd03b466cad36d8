// Link clustering (paper §III): split a cloud into connected components
// where two points are "linked" when their 3D Euclidean distance is at most
// `link_distance_mm`, then call every small component an outlier. This
// removes pulses (isolated points) and stripes (short chains at the edges of
// shadows) while keeping dents and dints, which stay linked to the surface
// around them. No coordinate is ever modified: the filter only removes.
//
// Two paths with the same semantics for "linked":
//  * organized grid (the fast path for sensor data): only 4- or 8-neighbours
//    in the sensor grid may link; a run-based two-pass union-find over the
//    grid, see link_clustering_grid.h;
//  * unorganized (the general path): every pair within the link distance
//    links, found with a sorted voxel grid (cells of edge d / sqrt(3), whose
//    points are all linked), see link_clustering_unorganized.h.
// Both give labels equal (up to renaming) to brute force; see the tests.
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

// The defaults are the paper's: they remove every outlier and may drop some
// good points, which is right before ICP (paper §III: fewer good points "will
// not change the calibration accuracy"). Before an error map, where dents
// must survive, use ForInspection(). Both are checked on simulated demo
// scans in tests/core/filter/link_clustering_groundtruth_test.cpp.
struct LinkClusteringSettings {
  // Two points link when |p - q| <= link_distance_mm (mm, finite, > 0). The
  // paper sets it "according to the resolution of area sensors", 0.1-0.5 mm.
  double link_distance_mm = 0.5;
  // Components with fewer valid points than this are outliers (the paper's
  // class-size criterion). 50 points is ~3 mm^2 of surface at 0.25 mm pitch:
  // far above a pulse (1 point) or a stripe chain (2-6 points per chain),
  // far below any surface patch worth inspecting.
  uint32_t min_cluster_points = 50;
  // Grid path only: 4 or 8 neighbours.
  int connectivity = 8;
  // Also an outlier: a component with fewer than this fraction of the
  // largest component's points. In [0, 1]; 0 = off.
  double min_fraction_of_largest = 0.0;

  // For scans that feed an error map. The demo sensor (1024 px over 35 deg)
  // has a 0.25 mm pitch at 400 mm, but pitch / cos(incidence) on steep
  // walls: at 0.5 mm those break into row fragments below 50 points, and
  // 0.3-0.4% of the dent points go. 0.85 mm links surfaces seen at up to
  // ~73 deg and stays below the >= 1 mm gap of mixed (stripe) pixels from
  // the near surface: >= 99.9% of dent points kept, ~1% of stripe points
  // too (linked to the far surface), which is why it is not the default:
  // before calibration those stray points pull the fit and cost accuracy.
  static LinkClusteringSettings ForInspection() {
    LinkClusteringSettings s;
    s.link_distance_mm = 0.85;
    return s;
  }
};

struct ClusterInfo {
  uint32_t size = 0;  // valid points in the component
  // Grid bounding box, inclusive (organized). For an unorganized cloud the
  // rows are 0 and the columns are the smallest and largest point index.
  uint32_t min_row = 0, min_col = 0, max_row = 0, max_col = 0;
  Eigen::Vector3f min{Eigen::Vector3f::Zero()};  // 3D bounding box, mm,
  Eigen::Vector3f max{Eigen::Vector3f::Zero()};  //   frame of the cloud
  bool kept = false;
};

struct LinkClusteringResult {
  // Per point: component id in [0, clusters.size()), or kInvalid for a point
  // without data. Ids are numbered in order of each component's first point.
  static constexpr int32_t kInvalid = -1;
  std::vector<int32_t> labels;
  std::vector<ClusterInfo> clusters;
  std::vector<uint8_t> kept_mask;  // per point: 1 = kept, 0 = removed or no data
  std::size_t input_points = 0;    // width * height
  std::size_t valid_points = 0;
  std::size_t kept = 0;
  std::size_t removed = 0;       // valid points in outlier components
  uint32_t largest_cluster = 0;  // size of the largest component (0 if none)
  bool organized_path = false;   // which path produced this
};

// The link predicate both paths (and their tests) use, in float arithmetic
// with a fixed order of operations so every path decides identically (the
// SSE row kernels repeat it exactly; x86-64's baseline has no FMA to fuse
// it). False when either point holds NaN.
inline bool PointsLinked(const Eigen::Vector3f& a, const Eigen::Vector3f& b,
                         float link_distance_sq) {
  const float dx = a.x() - b.x(), dy = a.y() - b.y(), dz = a.z() - b.z();
  return dx * dx + dy * dy + dz * dz <= link_distance_sq;
}
// The squared link distance as the paths compare it.
inline float LinkDistanceSquared(double link_distance_mm) {
  return static_cast<float>(link_distance_mm * link_distance_mm);
}

// Checks the settings: InvalidArgument naming the bad field.
absl::Status ValidateLinkClusteringSettings(const LinkClusteringSettings& settings);

// Organized cloud (height > 1) -> grid path, otherwise the unorganized path.
// Fails with InvalidArgument on bad settings, an empty cloud, a size that
// does not match width * height, or an infinite coordinate; Cancelled when
// `cancel` becomes true (checked once per grid row / batch of points).
absl::StatusOr<LinkClusteringResult> ClusterLinks(const PointCloud& cloud,
                                                  const LinkClusteringSettings& settings,
                                                  const std::atomic<bool>* cancel = nullptr);

// The same, reusing `result`'s buffers (no page faults on the steady state
// of a scan stream). On error `result` holds unspecified contents.
absl::Status ClusterLinksInto(const PointCloud& cloud, const LinkClusteringSettings& settings,
                              LinkClusteringResult& result,
                              const std::atomic<bool>* cancel = nullptr);

// The same cloud with every removed point set to NaN: an organized grid
// stays the same grid, and kept (and no-data) points are copied bit for bit.
// InvalidArgument when `result` does not cover this cloud (size mismatch).
absl::StatusOr<PointCloud> ApplyFilter(const PointCloud& cloud, const LinkClusteringResult& result);

// Clusters `cloud` (ClusterLinksInto) and sets every removed point to NaN in
// place, as ApplyFilter would: the one filter-then-apply step of every
// caller. `result` keeps the clustering (labels, clusters, counts, mask) for
// the caller's statistics and reuses its buffers. Errors as ClusterLinks;
// `cloud` is unchanged on error.
absl::Status RemoveOutliers(PointCloud& cloud, const LinkClusteringSettings& settings,
                            LinkClusteringResult& result,
                            const std::atomic<bool>* cancel = nullptr);

namespace internal {
// Shared by both paths once the clusters and their sizes are known: decides
// `kept` per cluster and fills the counts (not the mask).
void DecideClusters(const LinkClusteringSettings& settings, LinkClusteringResult& result);
// kept_mask from labels and the clusters' `kept` flags, point by point.
void FillKeptMaskFromLabels(LinkClusteringResult& result);
// Settings, emptiness and width * height checks shared by both paths (each
// path rejects infinite coordinates during its own first pass).
absl::Status CheckInput(const PointCloud& cloud, const LinkClusteringSettings& settings);
}  // namespace internal

}  // namespace surfinspect
