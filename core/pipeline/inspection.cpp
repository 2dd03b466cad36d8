#include "core/pipeline/inspection.h"

#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"
#include "core/errormap/error_map_output.h"
#include "core/errormap/error_map_png.h"
#include "core/types/cancel.h"
#include "core/types/transform.h"

namespace surfinspect {

absl::StatusOr<InspectionResult> InspectPart(const MeshIndex& part,
                                             const Eigen::Isometry3d& world_from_part,
                                             std::vector<ViewScan> views,
                                             const InspectionSettings& settings,
                                             const InspectionProgress& progress,
                                             const std::atomic<bool>* cancel) {
  if (views.empty()) return absl::InvalidArgumentError("inspect: no views");
  InspectionResult out;
  for (const ViewScan& v : views) {
    ViewOutcome outcome;
    outcome.name = v.name;
    outcome.valid_points = v.cloud_in_sensor.CountValid();
    out.views.push_back(outcome);
  }
  if (settings.filter) {
    std::size_t k = 0;
    auto on_view = [&](const ViewScan& v, const LinkClusteringResult& clusters) {
      out.views[k++].removed_points = clusters.removed;
      if (progress) progress(InspectionStage::kViewFiltered, v.name, clusters.kept);
    };
    if (auto st = FilterViews(views, settings.filter_settings, cancel, on_view); !st.ok())
      return st;
  }
  auto merged = RegisterToWorld(views, cancel);
  if (!merged.ok()) return merged.status();
  out.merged = *std::move(merged);
  if (progress)
    for (std::size_t k = 0; k < views.size(); ++k)
      progress(InspectionStage::kViewRegistered, views[k].name, out.merged.points_per_view[k]);
  if (IsCancelled(cancel)) return absl::CancelledError("inspect cancelled");
  auto map =
      ComputeErrorMap(part, out.merged.cloud_in_world, world_from_part, settings.error_map, cancel);
  if (!map.ok()) return map.status();
  out.error_map = *std::move(map);
  auto outcome = EvaluatePlan(out.error_map, out.merged.cloud_in_world, part.mesh(),
                              settings.plan ? *settings.plan : PlanFromSettings(settings.error_map),
                              settings.error_map.threads);
  if (!outcome.ok()) return outcome.status();
  out.plan = *std::move(outcome);
  if (progress) progress(InspectionStage::kErrorMap, "", out.error_map.stats.matched);
  return out;
}

std::string ErrorMapReportText(const ErrorMapResult& result, const ErrorMapSettings& settings,
                               const PlanOutcome& outcome) {
  return InspectionReportJson(result, settings, outcome).dump(2) + "\n";
}

absl::StatusOr<std::string> ErrorMapPngBytes(const PointCloud& cloud_in_world,
                                             const Eigen::Isometry3d& world_from_part,
                                             const ErrorMapResult& result,
                                             const TriangleMesh& part_in_part,
                                             const PlanOutcome& outcome) {
  const PointCloud in_part = TransformCloud(cloud_in_world, world_from_part.inverse());
  ErrorMapPngOptions options;
  options.defects = &outcome.defects.defects;
  options.part_pass = outcome.pass();
  auto image = RenderErrorMap(in_part, result, ComputeBounds(part_in_part), options);
  if (!image.ok()) return image.status();
  return EncodePng(*image);
}

}  // namespace surfinspect
