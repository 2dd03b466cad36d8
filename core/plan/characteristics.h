// Characteristics: the error map judged against an inspection plan. One
// result per characteristic: the whole surface ("surface", the plan's
// default band), each region, each comparison point; and the part verdict.
//
//  * Region membership of a scanned point is its closest CAD triangle's
//    (ResolvedInspectionPlan); a region is judged on the matched points in it.
//  * A comparison point's value is the mean signed deviation of the scanned
//    points whose closest CAD point lies within radius_mm of position_mm; it
//    has no value (failing) when there is none.
//  * A hole or slot passes when it was measured (its edge seen over at
//    least min_arc_deg), its true position is within its zone and its
//    diameter (a slot's width and length) deviates within its band.
//  * An edge point passes when it was measured and its offset is inside
//    its band.
//  * A surface, region or section passes when it has matched points and
//    the fraction outside its band is at most allowed_fraction_outside
//    (a section's points are those CutSection selected); a point passes
//    when it has a value and that value is inside its band.
//  * With a coverage (core/plan/coverage.h), a characteristic whose CAD
//    area was seen over less than its min_coverage is not measured: it
//    does not pass, whatever its few points say. A section whose cut
//    carries a coverage (SectionCoverage: of its curve's length) is judged
//    so against the plan's min_coverage.
//  * The part passes when every characteristic passes (those not measured
//    are let through only when the plan allows it), and, when the plan
//    sets defects.max_count, at most that many defects were found.
//
// One pass over the points, with the per-triangle rows of the resolved plan;
// accumulated in double over fixed chunks of points and reduced in chunk
// order, so the result does not depend on the thread count. The surface's
// min/max/mean/stddev/rms are the error map's own statistics. Deviations are
// mm, signed (+ above the CAD surface), positions in the part frame.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/errormap/error_map.h"
#include "core/plan/coverage.h"
#include "core/plan/edge_points.h"
#include "core/plan/holes.h"
#include "core/plan/inspection_plan.h"
#include "core/plan/section.h"

namespace surfinspect {

enum class CharacteristicType { kSurface, kRegion, kPoint, kSection, kHole, kSlot, kEdgePoint };
// "surface" | "region" | "point" | "section" | "hole" | "slot" | "edge_point"
const char* CharacteristicTypeName(CharacteristicType type);

struct CharacteristicResult {
  std::string name;
  CharacteristicType type = CharacteristicType::kSurface;
  bool pass = false;
  bool measured = true;     // false: coverage below min_coverage (never passes)
  double coverage = NAN;    // covered fraction of its CAD area; NaN when not computed
  double min_coverage = 0;  // the least it needed
  std::string reason;       // one line, for people
  ToleranceBand tolerance;
  double allowed_fraction_outside = 0;  // surface and regions
  std::size_t points = 0;               // matched points judged
  std::size_t within = 0, above = 0, below = 0;
  // Over those points, mm; NaN when there are none. stddev is the population one.
  double min_mm = NAN, max_mm = NAN, mean_mm = NAN, stddev_mm = NAN, rms_mm = NAN;
  double fraction_within = NAN;
  // Points: the mean; NaN when no point is near. Edge points: the edge's
  // offset across the CAD edge, + off the material.
  double value_mm = NAN;
  // Holes and slots: the measurement (core/plan/holes.h) and the true
  // position zone it was judged against; `tolerance` is the diameter's (a
  // slot's width's) band, `points` the edge points kept by the fit.
  HoleMeasurement hole;
  double position_tolerance_mm = NAN;
  ToleranceBand length_tolerance{NAN, NAN};  // slots only
  bool is_hole() const {
    return type == CharacteristicType::kHole || type == CharacteristicType::kSlot;
  }
};

struct CharacteristicsResult {
  // surface, regions, points, sections, holes and slots, edge points, in plan order
  std::vector<CharacteristicResult> characteristics;
  bool pass = false;       // every characteristic passes (and the defect count rule, when set)
  std::size_t failed = 0;  // characteristics that were measured and fail
  std::size_t not_measured = 0;
  std::string reason;
};

struct CharacteristicsSettings {
  int threads = 0;  // 0 = all cores; the result is the same for any value
};

// "pass" | "fail" | "not_measured".
const char* VerdictName(const CharacteristicResult& c);

// `error_map` must come from the part mesh `plan` was resolved against
// (triangle ids below plan.num_triangles); InvalidArgument otherwise.
// `defect_count` feeds the max_count rule; pass 0 when defects were not run.
// `coverage` (of the same plan and map) is judged when given. `sections`
// holds the plan's sections cut on the same map (CutSection), one per
// plan.sections entry; each is judged like a region on its points.
// `holes` holds one measurement per plan.holes entry (MeasureHoles),
// `edge_points` one per plan.edge_points entry (MeasureEdgePoints).
absl::StatusOr<CharacteristicsResult> ComputeCharacteristics(
    const ErrorMapResult& error_map, const ResolvedInspectionPlan& plan,
    std::size_t defect_count = 0, const CharacteristicsSettings& settings = {},
    const CoverageResult* coverage = nullptr, const std::vector<SectionCut>& sections = {},
    const std::vector<HoleMeasurement>& holes = {},
    const std::vector<EdgePointMeasurement>& edge_points = {});

}  // namespace surfinspect
