// World-frame registration (paper §II): in production every viewpoint's
// cloud goes straight into the world frame through its calibrated
// world_from_sensor. Only the robot's repeatability matters, and no fit to
// the CAD is made, so real shape errors stay in the data.
//
// An optional best fit of the merged cloud to the CAD (ICP against the part
// mesh) exists for users who ask for it. It is off by default because it
// "minimises" the very shape error the inspection is meant to find (paper
// §I); it returns the correction it applied so reports can show it.
#pragma once

#include <Eigen/Geometry>
#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/distance/mesh_index.h"
#include "core/filter/link_clustering.h"
#include "core/registration/icp.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

struct ViewScan {
  std::string name;                                                     // viewpoint name, e.g. "v1"
  PointCloud cloud_in_sensor;                                           // organized or not, mm
  Eigen::Isometry3d world_from_sensor = Eigen::Isometry3d::Identity();  // calibrated
};

struct MergedCloud {
  PointCloud cloud_in_world;         // valid points only, unorganized, mm
  std::vector<uint16_t> view_id;     // per point: index into view_names
  std::vector<uint32_t> grid_index;  // per point: row * width + col in its scan
  std::vector<std::string> view_names;
  std::vector<std::size_t> points_per_view;
};

// Link-clustering filter of every view's cloud, in place (RemoveOutliers),
// before RegisterToWorld. `on_view`, when given, sees each view with its
// clustering right after it is filtered. Errors as ClusterLinks, prefixed
// with the view's name.
using FilteredViewSink =
    std::function<void(const ViewScan& view, const LinkClusteringResult& clusters)>;
absl::Status FilterViews(std::vector<ViewScan>& views, const LinkClusteringSettings& settings,
                         const std::atomic<bool>* cancel = nullptr,
                         const FilteredViewSink& on_view = nullptr);

// Fails on an invalid cloud, a non-rigid transform, or more than 65535 views;
// Cancelled when `cancel` is raised (polled before each view: a view's work
// is mostly first touching the merged buffers, too long to run uncancelled).
absl::StatusOr<MergedCloud> RegisterToWorld(const std::vector<ViewScan>& views,
                                            const std::atomic<bool>* cancel = nullptr);

struct BestFitResult {
  // Maps registered world points to best-fitted world points
  // (world_fitted_from_world); apply it with TransformCloud.
  Eigen::Isometry3d correction = Eigen::Isometry3d::Identity();
  double translation_mm = 0;  // size of the correction
  double rotation_deg = 0;
  IcpResult icp;
};

// ICP of the merged cloud against the part mesh placed by world_from_part.
// Point-to-plane by default: the cloud already sits within ~1 mm.
IcpSettings DefaultBestFitSettings();
absl::StatusOr<BestFitResult> BestFitToCad(const MeshIndex& part_in_part,
                                           const Eigen::Isometry3d& world_from_part,
                                           const MergedCloud& merged,
                                           const IcpSettings& settings = DefaultBestFitSettings(),
                                           const std::atomic<bool>* cancel = nullptr);

}  // namespace surfinspect
