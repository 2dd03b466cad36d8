#include "core/registration/registration.h"

#include "absl/strings/str_cat.h"
#include "core/types/cancel.h"
#include "core/types/status_macros.h"
#include "core/types/transform.h"

namespace surfinspect {

absl::Status FilterViews(std::vector<ViewScan>& views, const LinkClusteringSettings& settings,
                         const std::atomic<bool>* cancel, const FilteredViewSink& on_view) {
  LinkClusteringResult clusters;  // buffers reused across views
  for (ViewScan& v : views) {
    if (auto st = RemoveOutliers(v.cloud_in_sensor, settings, clusters, cancel); !st.ok())
      return absl::Status(st.code(), absl::StrCat("view '", v.name, "': ", st.message()));
    if (on_view) on_view(v, clusters);
  }
  return absl::OkStatus();
}

absl::StatusOr<MergedCloud> RegisterToWorld(const std::vector<ViewScan>& views,
                                            const std::atomic<bool>* cancel) {
  if (views.empty()) return absl::InvalidArgumentError("register: no views");
  if (views.size() > 65535) return absl::InvalidArgumentError("register: more than 65535 views");
  MergedCloud out;
  std::size_t total = 0;
  for (const auto& v : views) {
    if (auto st = v.cloud_in_sensor.Validate(); !st.ok())
      return absl::InvalidArgumentError(
          absl::StrCat("register: view '", v.name, "': ", st.message()));
    // Re-check rigidity: a matrix that slipped past validation would scale
    // the part and fake a shape error.
    RETURN_IF_ERROR(
        FromRowMajor(ToRowMajor(v.world_from_sensor), "world_from_sensor of " + v.name).status());
    total += v.cloud_in_sensor.CountValid();
  }
  std::vector<Eigen::Vector3f> pts;
  pts.reserve(total);
  out.view_id.reserve(total);
  out.grid_index.reserve(total);
  for (std::size_t k = 0; k < views.size(); ++k) {
    if (IsCancelled(cancel)) return absl::CancelledError("register: cancelled");
    const ViewScan& v = views[k];
    out.view_names.push_back(v.name);
    const std::size_t before = pts.size();
    // Each point through the calibrated pose of the paper's eq. (1).
    v.cloud_in_sensor.ForEachValid([&](std::size_t i, const Eigen::Vector3f& p) {
      pts.push_back((v.world_from_sensor * p.cast<double>()).cast<float>());
      out.view_id.push_back(static_cast<uint16_t>(k));
      out.grid_index.push_back(static_cast<uint32_t>(i));
    });
    out.points_per_view.push_back(pts.size() - before);
  }
  out.cloud_in_world = PointCloud::Unorganized(std::move(pts));
  return out;
}

IcpSettings DefaultBestFitSettings() {
  IcpSettings s;
  s.step = IcpStep::kPointToPlane;
  s.max_correspondence_mm = 5.0;
  s.min_correspondence_mm = 0.5;
  s.max_iterations = 50;
  return s;
}

absl::StatusOr<BestFitResult> BestFitToCad(const MeshIndex& part,
                                           const Eigen::Isometry3d& world_from_part,
                                           const MergedCloud& merged, const IcpSettings& settings,
                                           const std::atomic<bool>* cancel) {
  ASSIGN_OR_RETURN(
      auto icp, RunIcp(part, merged.cloud_in_world, world_from_part.inverse(), settings, cancel));
  BestFitResult r;
  r.icp = std::move(icp);
  // part_from_world' is what ICP found; world_from_part maps it back, so the
  // correction moves registered world points onto the fitted ones.
  r.correction = world_from_part * r.icp.mesh_from_points;
  const PoseDifference d = ComparePoses(Eigen::Isometry3d::Identity(), r.correction);
  r.translation_mm = d.translation_mm;
  r.rotation_deg = d.rotation_deg;
  return r;
}

}  // namespace surfinspect
