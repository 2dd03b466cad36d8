// The error map judged against an inspection plan, for every caller (the
// CLI's errormap and inspect, the ErrorMap and Inspect RPCs, the cell-agent):
// the plan is resolved on the part mesh, defects are found when the plan
// asks for them (core/plan/defects.h), and every characteristic and the
// part verdict are computed (core/plan/characteristics.h). The report.json
// text is core/pipeline/inspection_report.h's, so every caller writes the
// same bytes.
//
// Without a plan a part is judged by PlanFromSettings: the whole surface
// against the error map's +-tolerance_mm and allowed_fraction_outside, so the
// part verdict is the tolerance verdict. Units mm, part frame.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "core/errormap/error_map.h"
#include "core/io/length_units.h"
#include "core/plan/alignment.h"
#include "core/plan/characteristics.h"
#include "core/plan/defects.h"
#include "core/plan/holes.h"
#include "core/plan/inspection_plan.h"
#include "core/types/point_cloud.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

// The plan of a caller without one: the surface only, band {-t, +t} and the
// settings' allowed_fraction_outside.
InspectionPlan PlanFromSettings(const ErrorMapSettings& settings);

// ParseInspectionPlan with the error-map settings as defaults: a plan
// without "tolerance_mm" takes {-t, +t} of settings.tolerance_mm, one without
// "allowed_fraction_outside" takes the settings' (the symmetric --tolerance
// is the shorthand of the plan's band). Group selectors name `groups` of the
// CAD file and come back as the triangle ids of their group.
absl::StatusOr<InspectionPlan> ParsePlanWithDefaults(const nlohmann::json& json,
                                                     const TriangleMesh& part,
                                                     const ErrorMapSettings& settings,
                                                     const std::string& where = "plan",
                                                     const MeshGroups& groups = {});

// ParsePlanWithDefaults with the groups of the CAD file `mesh_path` that
// `part` was read from (io_mesh.h ReadMeshGroups), in millimetres scaled from
// the file's `file_unit`. A file whose groups cannot
// be read has none; a plan that selects one is then refused with that reason.
absl::StatusOr<InspectionPlan> ParsePlanForMeshFile(const nlohmann::json& json,
                                                    const TriangleMesh& part,
                                                    const std::string& mesh_path,
                                                    const ErrorMapSettings& settings,
                                                    const std::string& where = "plan",
                                                    LengthUnit file_unit = LengthUnit::kMillimetre);

// The default coverage distance in sampling spacings: a CAD location within
// 4 spacings of a measured point was seen. A wall at 75 degrees incidence is
// sampled ~3.9x coarser along its slope; its farthest location from a
// sample is ~2 spacings away, so it still counts as seen.
inline constexpr double kCoverageSpacings = 4.0;

struct PlanOutcome {
  CharacteristicsResult characteristics;  // surface, regions, points
  std::vector<SectionCut> sections;       // per plan section: the nominal curve, whiskers
  bool coverage_run = false;              // PlanJudgesCoverage
  CoverageResult coverage;                // of the same characteristics, when run
  bool defects_run = false;               // the plan has defect rules
  DefectsResult defects;                  // empty unless defects_run
  AlignmentOutcome alignment;             // how the scan was aligned (calibrated: nothing done)
  bool pass() const { return characteristics.pass; }
};

// Whether any characteristic of the plan needs a least coverage; only then
// is coverage computed (a plan of min_coverage 0, and the plan of a caller
// without one, judge whatever was seen, as before coverage existed).
bool PlanJudgesCoverage(const InspectionPlan& plan);

// `cloud` is the cloud `error_map` was computed on (any frame), `part` the
// mesh it was computed against. `views` are the organized views the cloud
// was merged from, for holes and slots (core/plan/holes.h); without them a
// plan's holes are not measured. InvalidArgument (field named, "plan...")
// for a plan that does not fit the part; Cancelled when `cancel` is raised.
absl::StatusOr<PlanOutcome> EvaluatePlan(const ErrorMapResult& error_map, const PointCloud& cloud,
                                         const TriangleMesh& part, const InspectionPlan& plan,
                                         int threads = 0, const std::atomic<bool>* cancel = nullptr,
                                         const std::vector<PlanView>& views = {});

}  // namespace surfinspect
