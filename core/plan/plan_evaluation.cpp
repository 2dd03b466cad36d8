#include "core/plan/plan_evaluation.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <optional>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/io/io_mesh.h"
#include "core/plan/surface_neighbourhood.h"
#include "core/types/status_macros.h"

namespace surfinspect {

InspectionPlan PlanFromSettings(const ErrorMapSettings& settings) {
  InspectionPlan plan;
  plan.tolerance = {-settings.tolerance_mm, settings.tolerance_mm};
  plan.allowed_fraction_outside = settings.allowed_fraction_outside;
  // Without a plan the points given are judged (a single view of a part is
  // a valid error map); coverage is reported, not required.
  plan.min_coverage = 0;
  return plan;
}

absl::StatusOr<InspectionPlan> ParsePlanWithDefaults(const nlohmann::json& json,
                                                     const TriangleMesh& part,
                                                     const ErrorMapSettings& settings,
                                                     const std::string& where,
                                                     const MeshGroups& groups) {
  if (!json.is_object()) return absl::InvalidArgumentError(where + ": must be an object");
  nlohmann::json with = json;
  if (!with.contains("tolerance_mm"))
    with["tolerance_mm"] = {{"lower", -settings.tolerance_mm}, {"upper", settings.tolerance_mm}};
  if (!with.contains("allowed_fraction_outside"))
    with["allowed_fraction_outside"] = settings.allowed_fraction_outside;
  auto plan = ParseInspectionPlan(with, part, where, groups);
  if (plan.ok()) SelectGroupsByTriangles(&*plan, groups);
  return plan;
}

absl::StatusOr<InspectionPlan> ParsePlanForMeshFile(
    const nlohmann::json& json, const TriangleMesh& part, const std::string& mesh_path,
    const ErrorMapSettings& settings, const std::string& where, LengthUnit file_unit) {
  const absl::StatusOr<MeshGroups> groups = ReadMeshGroups(mesh_path, part, {}, file_unit);
  auto plan =
      ParsePlanWithDefaults(json, part, settings, where, groups.ok() ? *groups : MeshGroups{});
  if (plan.ok() || groups.ok()) return plan;
  return absl::Status(plan.status().code(),
                      absl::StrCat(plan.status().message(), " (", groups.status().message(), ")"));
}

namespace {

// f() run in `arena` (its threads), its result returned.
template <typename F>
auto InArena(tbb::task_arena& arena, F&& f) {
  decltype(f()) result;
  arena.execute([&] { result = f(); });
  return result;
}

// Each section of the plan cut on the map, limited to its region's
// triangles; the sections in parallel (the caller's arena), each in its
// slot, the first failure in plan order returned.
absl::StatusOr<std::vector<SectionCut>> CutSections(const ErrorMapResult& em,
                                                    const TriangleMesh& part,
                                                    const ResolvedInspectionPlan& rp,
                                                    const TrianglePoints* by_triangle) {
  const std::vector<PlanSection>& sections = rp.plan.sections;
  std::vector<absl::StatusOr<SectionCut>> cuts(sections.size());
  tbb::parallel_for(std::size_t{0}, sections.size(), [&](std::size_t i) {
    const PlanSection& s = sections[i];
    std::vector<uint8_t> mask;
    for (std::size_t r = 0; r < rp.plan.regions.size() && !s.region.empty(); ++r) {
      if (rp.plan.regions[r].name != s.region) continue;
      mask.assign(rp.num_triangles, 0);
      for (std::size_t t = 0; t < rp.num_triangles; ++t)
        for (uint32_t k = rp.region_offsets[t]; k < rp.region_offsets[t + 1]; ++k)
          mask[t] |= rp.region_ids[k] == r;
    }
    cuts[i] = CutSection(part, em, {s.point_mm, s.normal, s.width_mm}, mask, kDefaultMaxWhiskers,
                         by_triangle);
  });
  std::vector<SectionCut> out;
  for (auto& cut : cuts) {
    if (!cut.ok()) return cut.status();
    out.push_back(std::move(*cut));
  }
  return out;
}

}  // namespace

bool PlanJudgesCoverage(const InspectionPlan& plan) {
  bool any = plan.min_coverage > 0;
  for (const PlanRegion& r : plan.regions) any |= r.min_coverage.value_or(plan.min_coverage) > 0;
  for (const ComparisonPoint& p : plan.points)
    any |= p.min_coverage.value_or(plan.min_coverage) > 0;
  return any;
}

absl::StatusOr<PlanOutcome> EvaluatePlan(const ErrorMapResult& error_map, const PointCloud& cloud,
                                         const TriangleMesh& part, const InspectionPlan& plan,
                                         int threads, const std::atomic<bool>* cancel,
                                         const std::vector<PlanView>& views) {
  ASSIGN_OR_RETURN(auto resolved, ResolveInspectionPlan(plan, part));
  PlanOutcome out;
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  // The sampling spacing, estimated once for coverage and defects alike.
  const bool coverage = PlanJudgesCoverage(plan);
  const double spacing = coverage || plan.defects ? EstimateSurfaceSpacing(error_map, cloud) : 0.0;
  // The points by triangle, once for coverage and sections.
  std::optional<TrianglePoints> by_triangle;
  if (coverage || !plan.sections.empty()) {
    ASSIGN_OR_RETURN(by_triangle, InArena(arena, [&] {
                       return PointsByTriangle(error_map, part.num_triangles());
                     }));
  }
  const TrianglePoints* grouped = by_triangle ? &*by_triangle : nullptr;
  if (coverage) {
    CoverageSettings cov;
    cov.distance_mm =
        plan.coverage_distance_mm > 0 ? plan.coverage_distance_mm : kCoverageSpacings * spacing;
    cov.threads = threads;
    ASSIGN_OR_RETURN(out.coverage,
                     ComputeCoverage(error_map, part, resolved, cov, cancel, grouped));
    out.coverage_run = true;
  }
  if (plan.defects) {
    DefectSettings ds;
    ds.spacing_mm = spacing;
    ds.threads = threads;
    ASSIGN_OR_RETURN(out.defects,
                     FindDefects(error_map, cloud, part, *plan.defects, &resolved, ds));
    out.defects_run = true;
  }
  ASSIGN_OR_RETURN(out.sections,
                   InArena(arena, [&] { return CutSections(error_map, part, resolved, grouped); }));
  if (coverage)  // a section's curve is judged like an area
    for (SectionCut& cut : out.sections)
      cut.coverage = SectionCoverage(cut, error_map, out.coverage.distance_mm);
  // The views' pixel rays, fitted once for holes and edge points.
  const std::vector<RayView> rays = plan.holes.empty() && plan.edge_points.empty()
                                        ? std::vector<RayView>{}
                                        : InArena(arena, [&] { return PrepareRayViews(views); });
  ASSIGN_OR_RETURN(auto holes, InArena(arena, [&] {
                     return MeasureHoles(resolved.plan.holes, views, {}, cancel, &rays);
                   }));
  ASSIGN_OR_RETURN(auto edges,
                   MeasureEdgePoints(resolved.plan.edge_points, part, views, {}, cancel, &rays));
  CharacteristicsSettings cs;
  cs.threads = threads;
  ASSIGN_OR_RETURN(out.characteristics,
                   ComputeCharacteristics(error_map, resolved, out.defects.defects.size(), cs,
                                          out.coverage_run ? &out.coverage : nullptr, out.sections,
                                          holes, edges));
  if (plan.alignment.mode != AlignmentMode::kCalibrated) {
    // The error map is given: nothing here can map the scan again.
    out.alignment.mode = plan.alignment.mode;
    out.alignment.failure =
        "the error map alone cannot be aligned again; inspect aligns the part from its views";
    ApplyAlignmentVerdict(out.alignment, &out.characteristics);
  }
  return out;
}

}  // namespace surfinspect
