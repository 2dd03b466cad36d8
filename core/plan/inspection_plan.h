// The inspection plan: what a part is judged on, in the part (CAD) frame, mm.
//
//  * a default tolerance band {lower, upper} for the whole surface (the
//    characteristic named "surface");
//  * regions of the CAD surface, each with its own (often asymmetric) band,
//    selected by a box (a triangle is in it when its centroid is), by
//    triangle ids, or by a named group of the CAD file; regions may overlap;
//  * comparison points at taught positions, each judged on the mean signed
//    deviation of the scanned points whose closest CAD point lies within
//    radius_mm of it;
//  * defect detection rules (core/plan/defects.h).
//
// The JSON format ("schema": "surfinspect.plan/1") is documented in
// docs/inspection-plan.md. One validator, ValidateInspectionPlan, checks the
// struct for every source (the JSON parser here, the wire conversion); its
// messages name the field as a JSON path, e.g.
// "plan.regions[1].select.box_mm: empty or inverted box".
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/plan/cad_holes.h"
#include "core/registration/rigid_dofs.h"
#include "core/types/mesh_groups.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

inline constexpr char kInspectionPlanSchema[] = "surfinspect.plan/1";
// The whole surface's characteristic; no region or point may take this name.
inline constexpr char kSurfaceCharacteristicName[] = "surface";

// lower <= deviation <= upper, mm, signed (+ above the CAD surface).
// Deviations are float32, so Contains() rounds the edges to float32 first:
// a deviation that prints as the edge value is inside the band. Both
// edges are compared (&, not &&): no branch on the lower edge, which
// mispredicts where a failing part's points fall on either side at random.
struct ToleranceBand {
  double lower_mm = -0.1;
  double upper_mm = 0.1;
  bool Contains(float deviation_mm) const {
    return (deviation_mm >= static_cast<float>(lower_mm)) &
           (deviation_mm <= static_cast<float>(upper_mm));
  }
};

struct RegionSelector {
  enum class Kind { kBox, kTriangles, kGroup };
  Kind kind = Kind::kBox;
  Eigen::Vector3d box_min_mm = Eigen::Vector3d::Zero();  // kBox: part frame, inclusive
  Eigen::Vector3d box_max_mm = Eigen::Vector3d::Zero();
  std::vector<uint32_t> triangles;  // kTriangles: ids into the part mesh
  std::string group;                // kGroup: a name in MeshGroups::names
};

struct PlanRegion {
  std::string name;
  RegionSelector select;
  std::optional<ToleranceBand> tolerance;  // unset: the plan's default band
  double allowed_fraction_outside = 0.0;   // of the region's matched points, in [0, 1]
  std::optional<double> min_coverage;      // unset: the plan's; in [0, 1]
};

struct ComparisonPoint {
  std::string name;
  Eigen::Vector3d position_mm = Eigen::Vector3d::Zero();  // part frame, on or near the surface
  // The taught surface normal (unit after parsing), or zero when not given.
  // Informational: the value is the signed deviation along the CAD normal.
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double radius_mm = 2.0;  // > 0
  std::optional<ToleranceBand> tolerance;
  std::optional<double> min_coverage;  // of the surface within radius_mm; unset: the plan's
  // A directional point (e.g. the stamping direction; unit after parsing):
  // its value is the deviation measured along this direction, d / (n . a)
  // for a point of normal deviation d on a CAD face of normal n, instead of
  // along the normal. Zero: along the normal.
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
};

// A section through the part (core/plan/section.h): judged on the matched
// points whose closest CAD point lies within +-width_mm/2 of the plane, like
// a region; limited to a region of this plan when `region` names one.
struct PlanSection {
  std::string name;
  Eigen::Vector3d point_mm = Eigen::Vector3d::Zero();  // on the plane, part frame
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();   // unit after parsing
  double width_mm = 1.0;                               // > 0
  std::string region;                                  // "" = the whole part
  std::optional<ToleranceBand> tolerance;              // unset: the plan's band
  double allowed_fraction_outside = 0.0;               // in [0, 1]
};

// A hole's edge seen over less than this arc is not measured: a circle fitted
// to less than half its edge is poorly conditioned in diameter and centre.
inline constexpr double kDefaultMinArcDeg = 180;

// A hole or a slot of the drawing (core/plan/holes.h), measured at its edge
// on the scan. Nominal in the part frame: the centre in the plane of the
// rim, the axis (unit after parsing; the side the sheet's scanned face looks
// to), the diameter (a slot's width) and a slot's overall length and
// length direction. Judged by its true position (2 x the radial deviation
// of the centre, ISO 1101) and its size deviation(s).
struct PlanHole {
  std::string name;
  bool slot = false;
  Eigen::Vector3d position_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  double diameter_mm = 0;                               // > 0; a slot's width
  double length_mm = 0;                                 // slot: > diameter_mm
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // slot: unit after parsing, normal to axis
  double position_tolerance_mm = 0.2;                   // true position zone diameter, > 0
  ToleranceBand diameter_tolerance{-0.1, 0.1};          // of the diameter (a slot's width)
  ToleranceBand length_tolerance{-0.2, 0.2};            // slot only
  double min_arc_deg = kDefaultMinArcDeg;               // seen over less: not measured
};

// A point on the CAD's trim edge (its boundary: an edge used by one
// triangle), judged on where the measured edge lies across the nominal one
// in the face's plane (core/plan/edge_points.h): + off the material (the
// sheet reaches farther than drawn), - into it.
struct PlanEdgePoint {
  std::string name;
  Eigen::Vector3d position_mm = Eigen::Vector3d::Zero();  // on or near the boundary, part frame
  double radius_mm = 5.0;                                 // sampled within +-radius along the edge
  ToleranceBand tolerance{-0.5, 0.5};
};

struct DefectRules {
  double threshold_mm = 0.05;  // |robust local deviation| above this is defective; > 0
  double min_area_mm2 = 3.0;   // smaller patches are not reported; >= 0
  // When set, the part fails with more than max_count defects; unset, defects
  // never change the verdict.
  std::optional<int> max_count;
};

// How the scan is aligned to the CAD before anything is judged
// (core/plan/alignment.h, docs/alignment.md). `calibrated`: the cell's
// calibrated transforms alone (the paper's, §II); `rps`: the drawing's
// reference points, each locking some directions; `best_fit`: a robust
// point-to-plane fit with locked degrees of freedom, optionally on some
// regions. The correction is a result; beyond its allowed size the part
// fails.
enum class AlignmentMode { kCalibrated, kRps, kBestFit };
// "calibrated" | "rps" | "best_fit".
const char* AlignmentModeName(AlignmentMode mode);

// An RPS reference: a plan hole (a hole locks the two directions of its
// plane, a slot the one across its length) or a surface point (locks the
// CAD normal there; measured as the median deviation of the points whose
// closest CAD point lies within radius_mm of it).
struct AlignmentReference {
  std::string name;
  std::string hole;                                       // a plan hole's or slot's name, or "":
  Eigen::Vector3d position_mm = Eigen::Vector3d::Zero();  // a surface point, part frame
  double radius_mm = 3.0;                                 // > 0
};

struct PlanAlignment {
  AlignmentMode mode = AlignmentMode::kCalibrated;
  std::vector<AlignmentReference> references;  // rps: locking all six degrees of freedom
  std::vector<std::string> regions;            // best_fit: fitted on these; empty = the part
  LockedDofs locked;                           // best_fit: held at zero
  // The allowed correction: the largest displacement of a reference (of a
  // used point, for best_fit), mm, and the rotation angle, degrees; > 0.
  double max_correction_mm = 2.0;
  double max_correction_deg = 1.0;
};

// A plan's default least coverage: a characteristic whose CAD area was seen
// over less is not measured. docs/inspection-plan.md gives the reasons.
inline constexpr double kDefaultMinCoverage = 0.9;

struct InspectionPlan {
  ToleranceBand tolerance;                // the surface's band and the default
  double allowed_fraction_outside = 0.0;  // for the surface characteristic
  // Coverage (core/plan/coverage.h): the least covered fraction of each
  // characteristic's CAD area (the surface, a region, a point's disc) for
  // it to be measured; in [0, 1], 0 judges whatever was seen. The distance
  // within which a measured point covers the CAD, mm; 0 = 4 sampling
  // spacings of the scan. A characteristic not measured fails the part
  // unless allow_not_measured.
  double min_coverage = kDefaultMinCoverage;
  double coverage_distance_mm = 0;
  bool allow_not_measured = false;
  std::vector<PlanRegion> regions;
  std::vector<ComparisonPoint> points;
  std::vector<PlanSection> sections;
  std::vector<PlanHole> holes;  // holes, then slots, in plan order
  std::vector<PlanEdgePoint> edge_points;
  std::optional<DefectRules> defects;  // unset: no defect detection
  PlanAlignment alignment;
};

// Checks the plan against the part it will be applied to: finite numbers,
// lower <= upper, a non-empty box with min <= max, radius > 0, fractions in
// [0, 1], triangle ids in range, groups that exist, non-empty names unique
// across regions and points and not "surface". InvalidArgument, the message
// starting with `where` and the field's path.
absl::Status ValidateInspectionPlan(const InspectionPlan& plan, const TriangleMesh& part,
                                    const MeshGroups& groups = {},
                                    const std::string& where = "plan");

// Parses the JSON form and validates it. Unknown keys and wrong types are
// refused with the field named; "schema", when present, must be
// "surfinspect.plan/1".
absl::StatusOr<InspectionPlan> ParseInspectionPlan(const nlohmann::json& json,
                                                   const TriangleMesh& part,
                                                   const std::string& where = "plan",
                                                   const MeshGroups& groups = {});

// Plan entries for the CAD's holes (ListHoles), to start a plan from:
// {"holes": [...], "slots": [...]}, named H1.. and S1.. in list order, with
// the default tolerances of PlanHole except the true-position zone given.
nlohmann::json PlanHolesJson(const std::vector<CadHole>& holes, double position_tolerance_mm);

// The plan applied to a mesh: which regions each triangle belongs to, and
// which comparison points each triangle can reach (a triangle within
// radius_mm of the point's position), both as compressed rows.
struct ResolvedInspectionPlan {
  InspectionPlan plan;
  std::size_t num_triangles = 0;
  // Regions of triangle t: region_ids[region_offsets[t] .. region_offsets[t+1]).
  std::vector<uint32_t> region_offsets;
  std::vector<uint32_t> region_ids;
  // Comparison points triangle t can reach, likewise.
  std::vector<uint32_t> point_offsets;
  std::vector<uint32_t> point_ids;
  // Per entry of point_ids: the factor from a normal deviation on that
  // triangle to the point's value, 1 / (n . direction); NaN where the
  // direction is within 10 degrees of the face (the surface cannot be met
  // along it). Empty when no point has a direction (every factor 1).
  std::vector<float> point_scale;
  std::vector<std::size_t> region_triangle_count;  // per region

  // The first region (plan order) containing triangle t, or -1.
  int FirstRegionOf(uint32_t t) const {
    if (t >= num_triangles || region_offsets[t] == region_offsets[t + 1]) return -1;
    return static_cast<int>(region_ids[region_offsets[t]]);
  }
};

// Turns every group selector into the triangle ids of its group, so the plan
// no longer needs the CAD file's groups (a server gets the plan, not the
// file). The plan was validated against `groups`.
void SelectGroupsByTriangles(InspectionPlan* plan, const MeshGroups& groups);

// Validates, then resolves. Region ids per triangle are in increasing order.
absl::StatusOr<ResolvedInspectionPlan> ResolveInspectionPlan(const InspectionPlan& plan,
                                                             const TriangleMesh& part,
                                                             const MeshGroups& groups = {});

}  // namespace surfinspect
