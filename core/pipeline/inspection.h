// Whole-part inspection, the paper's automatic data processing end to end:
// each viewpoint's scan is filtered by link clustering (§III), put into the
// world frame by its calibrated world_from_sensor (§II), the clouds are
// merged, and the merged cloud's signed error map against the CAD is
// computed (§IV). The CLI (in-process), the gRPC Inspect stream and the
// cell-agent's results all come from this one function.
#pragma once

#include <atomic>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/distance/mesh_index.h"
#include "core/errormap/error_map.h"
#include "core/filter/link_clustering.h"
#include "core/plan/plan_evaluation.h"
#include "core/registration/registration.h"

namespace surfinspect {

struct InspectionSettings {
  bool filter = true;  // link-clustering filter per view
  // The inspection preset, not the paper's 0.5 mm: before an error map no
  // dent point may be lost, and at 0.5 mm steep walls break into small
  // strips that the size criterion removes (link_clustering.h).
  LinkClusteringSettings filter_settings = LinkClusteringSettings::ForInspection();
  ErrorMapSettings error_map;
  // What the part is judged on; unset: PlanFromSettings(error_map).
  std::optional<InspectionPlan> plan;
};

enum class InspectionStage { kViewFiltered, kViewRegistered, kErrorMap };

struct ViewOutcome {
  std::string name;
  std::size_t valid_points = 0;    // before filtering
  std::size_t removed_points = 0;  // by the filter
};

struct InspectionResult {
  MergedCloud merged;        // world frame; traces back to view + pixel
  ErrorMapResult error_map;  // per merged point
  PlanOutcome plan;          // characteristics, defects and the part verdict
  std::vector<ViewOutcome> views;
};

// Called from the calling thread as each stage completes.
using InspectionProgress =
    std::function<void(InspectionStage stage, const std::string& view, std::size_t points)>;

absl::StatusOr<InspectionResult> InspectPart(const MeshIndex& part_in_part,
                                             const Eigen::Isometry3d& world_from_part,
                                             std::vector<ViewScan> views,
                                             const InspectionSettings& settings,
                                             const InspectionProgress& progress = {},
                                             const std::atomic<bool>* cancel = nullptr);

}  // namespace surfinspect
