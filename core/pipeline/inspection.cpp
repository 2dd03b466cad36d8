#include "core/pipeline/inspection.h"

#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"
#include "core/types/cancel.h"
#include "core/types/status_macros.h"
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
    RETURN_IF_ERROR(FilterViews(views, settings.filter_settings, cancel, on_view));
  }
  ASSIGN_OR_RETURN(auto merged, RegisterToWorld(views, cancel));
  out.merged = std::move(merged);
  if (progress)
    for (std::size_t k = 0; k < views.size(); ++k)
      progress(InspectionStage::kViewRegistered, views[k].name, out.merged.points_per_view[k]);
  if (IsCancelled(cancel)) return absl::CancelledError("inspect cancelled");
  const InspectionPlan plan = settings.plan ? *settings.plan : PlanFromSettings(settings.error_map);
  // The views as the plan measures holes and edges on them: filtered, in the
  // part frame as calibrated.
  std::vector<PlanView> plan_views;
  const bool edges = !plan.holes.empty() || !plan.edge_points.empty() ||
                     plan.alignment.mode == AlignmentMode::kRps;
  if (edges)
    for (const ViewScan& v : views)
      plan_views.push_back(
          {v.name, &v.cloud_in_sensor, world_from_part.inverse() * v.world_from_sensor});
  // The plan's alignment, measured on the scan as calibrated; the scan is
  // then mapped once, in the frame it gives.
  const AlignmentInputs aligning{
      part,       out.merged.cloud_in_world,          world_from_part,
      plan_views, settings.error_map.max_distance_mm, settings.error_map.threads};
  ASSIGN_OR_RETURN(AlignmentOutcome alignment, MeasureAlignment(aligning, plan, cancel));
  Eigen::Isometry3d frame = world_from_part;
  if (alignment.aligned) {
    frame = world_from_part * alignment.correction.inverse();
    for (PlanView& v : plan_views) v.part_from_sensor = alignment.correction * v.part_from_sensor;
  }
  ASSIGN_OR_RETURN(out.error_map, ComputeErrorMap(part, out.merged.cloud_in_world, frame,
                                                  settings.error_map, cancel));
  InspectionPlan judged = plan;  // aligned here, so judged as it now stands
  judged.alignment = PlanAlignment{};
  ASSIGN_OR_RETURN(out.plan, EvaluatePlan(out.error_map, out.merged.cloud_in_world, part.mesh(),
                                          judged, settings.error_map.threads, cancel, plan_views));
  ApplyAlignmentVerdict(alignment, &out.plan.characteristics);
  out.plan.alignment = std::move(alignment);
  if (progress) progress(InspectionStage::kErrorMap, "", out.error_map.stats.matched);
  return out;
}

}  // namespace surfinspect
