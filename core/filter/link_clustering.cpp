#include "core/filter/link_clustering.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"
#include "core/filter/link_clustering_grid.h"
#include "core/filter/link_clustering_unorganized.h"
#include "core/types/cancel.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

constexpr int32_t kInvalid = LinkClusteringResult::kInvalid;

// Only removed points change; no-data pixels keep their exact bits too.
// `result` covers `cloud` point for point.
void SetRemovedToNaN(const LinkClusteringResult& result, PointCloud& cloud) {
  const Eigen::Vector3f nan = Eigen::Vector3f::Constant(NAN);
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (!result.kept_mask[i] && result.labels[i] != kInvalid) cloud.points[i] = nan;
}

}  // namespace

absl::Status ValidateLinkClusteringSettings(const LinkClusteringSettings& s) {
  if (!(std::isfinite(s.link_distance_mm) && s.link_distance_mm > 0.0))
    return absl::InvalidArgumentError(absl::StrCat(
        "link clustering: link_distance_mm must be finite and > 0, got ", s.link_distance_mm));
  if (s.link_distance_mm > 1e6)
    return absl::InvalidArgumentError(absl::StrCat(
        "link clustering: link_distance_mm = ", s.link_distance_mm, " is absurd (> 1 km)"));
  if (s.connectivity != 4 && s.connectivity != 8)
    return absl::InvalidArgumentError(
        absl::StrCat("link clustering: connectivity must be 4 or 8, got ", s.connectivity));
  if (!(s.min_fraction_of_largest >= 0.0 && s.min_fraction_of_largest <= 1.0))
    return absl::InvalidArgumentError(
        absl::StrCat("link clustering: min_fraction_of_largest must be in [0, 1], got ",
                     s.min_fraction_of_largest));
  return absl::OkStatus();
}

namespace internal {

absl::Status CheckInput(const PointCloud& cloud, const LinkClusteringSettings& settings) {
  RETURN_IF_ERROR(ValidateLinkClusteringSettings(settings));
  if (cloud.empty() || cloud.width == 0 || cloud.height == 0)
    return absl::InvalidArgumentError(absl::StrCat(
        "link clustering: the cloud has no points (grid ", cloud.width, " x ", cloud.height, ")"));
  if (std::size_t{cloud.width} * cloud.height != cloud.size())
    return absl::InvalidArgumentError(absl::StrCat("link clustering: width*height = ", cloud.width,
                                                   "*", cloud.height, " does not match ",
                                                   cloud.size(), " points"));
  // Labels are int32 pixel indices during pass 1.
  if (cloud.size() > static_cast<std::size_t>(std::numeric_limits<int32_t>::max()))
    return absl::InvalidArgumentError(
        absl::StrCat("link clustering: ", cloud.size(), " points exceed the 2^31 - 1 limit"));
  return absl::OkStatus();
}

void DecideClusters(const LinkClusteringSettings& settings, LinkClusteringResult& result) {
  uint32_t largest = 0;
  for (const ClusterInfo& k : result.clusters) largest = std::max(largest, k.size);
  result.largest_cluster = largest;
  // The paper's class-size criterion, plus the optional relative one.
  const double by_fraction = settings.min_fraction_of_largest * largest;
  std::size_t kept = 0, valid = 0;
  for (ClusterInfo& k : result.clusters) {
    k.kept = k.size >= settings.min_cluster_points && static_cast<double>(k.size) >= by_fraction;
    valid += k.size;
    if (k.kept) kept += k.size;
  }
  result.valid_points = valid;
  result.kept = kept;
  result.removed = valid - kept;
}

void FillKeptMaskFromLabels(LinkClusteringResult& result) {
  const std::size_t n = result.labels.size();
  result.kept_mask.resize(n);
  uint8_t* __restrict mask = result.kept_mask.data();
  const int32_t* __restrict labels = result.labels.data();
  const ClusterInfo* clusters = result.clusters.data();
  for (std::size_t i = 0; i < n; ++i) mask[i] = labels[i] != kInvalid && clusters[labels[i]].kept;
}

}  // namespace internal

absl::Status ClusterLinksInto(const PointCloud& cloud, const LinkClusteringSettings& settings,
                              LinkClusteringResult& result, const std::atomic<bool>* cancel) {
  if (cloud.organized()) return ClusterLinksOrganized(cloud, settings, result, cancel);
  return ClusterLinksUnorganized(cloud, settings, result, cancel);
}

absl::StatusOr<LinkClusteringResult> ClusterLinks(const PointCloud& cloud,
                                                  const LinkClusteringSettings& settings,
                                                  const std::atomic<bool>* cancel) {
  LinkClusteringResult result;
  RETURN_IF_ERROR(ClusterLinksInto(cloud, settings, result, cancel));
  return result;
}

absl::StatusOr<PointCloud> ApplyFilter(const PointCloud& cloud,
                                       const LinkClusteringResult& result) {
  if (result.kept_mask.size() != cloud.size() || result.labels.size() != cloud.size())
    return absl::InvalidArgumentError(absl::StrCat("apply filter: the result covers ",
                                                   result.labels.size(),
                                                   " points but the cloud has ", cloud.size()));
  PointCloud out = cloud;
  SetRemovedToNaN(result, out);
  return out;
}

absl::Status RemoveOutliers(PointCloud& cloud, const LinkClusteringSettings& settings,
                            LinkClusteringResult& result, const std::atomic<bool>* cancel) {
  RETURN_IF_ERROR(ClusterLinksInto(cloud, settings, result, cancel));
  if (IsCancelled(cancel)) return absl::CancelledError("link clustering: cancelled");
  SetRemovedToNaN(result, cloud);
  return absl::OkStatus();
}

}  // namespace surfinspect
