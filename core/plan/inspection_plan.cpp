#include "core/plan/inspection_plan.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/distance/point_triangle.h"
#include "core/plan/cad_holes.h"
#include "core/plan/plan_alignment.h"
#include "core/plan/plan_json_read.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

using plan_json::Bad;
using plan_json::Index;

// ---- validation of the struct --------------------------------------------

absl::Status CheckFinite(const std::string& path, double v) {
  return std::isfinite(v) ? absl::OkStatus() : Bad(path, "not a finite number");
}

absl::Status CheckBand(const std::string& path, const ToleranceBand& b) {
  RETURN_IF_ERROR(CheckFinite(path + ".lower", b.lower_mm));
  RETURN_IF_ERROR(CheckFinite(path + ".upper", b.upper_mm));
  if (b.lower_mm > b.upper_mm)
    return Bad(path, absl::StrCat("lower (", b.lower_mm, ") > upper (", b.upper_mm, ")"));
  return absl::OkStatus();
}

absl::Status CheckFraction(const std::string& path, double f) {
  RETURN_IF_ERROR(CheckFinite(path, f));
  return f >= 0 && f <= 1 ? absl::OkStatus() : Bad(path, "must be in [0, 1]");
}

absl::Status CheckSelector(const std::string& path, const RegionSelector& s,
                           const TriangleMesh& part, const MeshGroups& groups) {
  switch (s.kind) {
    case RegionSelector::Kind::kBox:
      if (!s.box_min_mm.allFinite() || !s.box_max_mm.allFinite())
        return Bad(path + ".box_mm", "not a finite number");
      if ((s.box_min_mm.array() >= s.box_max_mm.array()).any())
        return Bad(path + ".box_mm", "empty or inverted box (need min < max on every axis)");
      return absl::OkStatus();
    case RegionSelector::Kind::kTriangles:
      if (s.triangles.empty()) return Bad(path + ".triangles", "empty list");
      for (std::size_t i = 0; i < s.triangles.size(); ++i)
        if (s.triangles[i] >= part.num_triangles())
          return Bad(Index(path + ".triangles", i),
                     absl::StrCat("triangle id ", s.triangles[i], " out of range (the part has ",
                                  part.num_triangles(), " triangles)"));
      return absl::OkStatus();
    case RegionSelector::Kind::kGroup:
      if (std::find(groups.names.begin(), groups.names.end(), s.group) == groups.names.end())
        return Bad(path + ".group", absl::StrCat("unknown group \"", s.group, "\" (the part has ",
                                                 groups.names.size(), " named groups)"));
      return absl::OkStatus();
  }
  return Bad(path, "unknown selector");
}

absl::Status CheckName(const std::string& path, const std::string& name,
                       std::set<std::string>& seen) {
  if (name.empty()) return Bad(path, "empty name");
  if (name == kSurfaceCharacteristicName)
    return Bad(path, "\"surface\" is reserved for the whole surface");
  if (!seen.insert(name).second)
    return Bad(path,
               absl::StrCat("duplicate name \"", name, "\" (characteristics share one namespace)"));
  return absl::OkStatus();
}

// ---- resolution ----------------------------------------------------------

bool InRegion(const RegionSelector& s, uint32_t t, const Eigen::Vector3d& centroid,
              const MeshGroups& groups, uint32_t group_index) {
  switch (s.kind) {
    case RegionSelector::Kind::kBox:
      return (centroid.array() >= s.box_min_mm.array()).all() &&
             (centroid.array() <= s.box_max_mm.array()).all();
    case RegionSelector::Kind::kTriangles:
      return std::binary_search(s.triangles.begin(), s.triangles.end(), t);
    case RegionSelector::Kind::kGroup:
      return groups.Contains(t, group_index);
  }
  return false;
}

// Compressed rows from a per-row membership test, rows in order, ids ascending.
template <typename F>
void BuildRows(std::size_t rows, std::size_t ids, F member, std::vector<uint32_t>& offsets,
               std::vector<uint32_t>& out) {
  offsets.assign(1, 0);
  for (std::size_t r = 0; r < rows; ++r) {
    for (std::size_t k = 0; k < ids; ++k)
      if (member(r, k)) out.push_back(static_cast<uint32_t>(k));
    offsets.push_back(static_cast<uint32_t>(out.size()));
  }
}

// ResolvedInspectionPlan::point_scale.
std::vector<float> DirectionScales(const ResolvedInspectionPlan& r, const TriangleMesh& part) {
  constexpr double kMinCosine = 0.1736;  // cos 80 degrees
  bool any = false;
  for (const ComparisonPoint& p : r.plan.points) any |= p.direction != Eigen::Vector3d::Zero();
  if (!any) return {};
  const std::vector<Eigen::Vector3f> normals = part.FaceNormals();
  std::vector<float> scale(r.point_ids.size(), 1.f);
  for (std::size_t t = 0; t < r.num_triangles; ++t)
    for (uint32_t k = r.point_offsets[t]; k < r.point_offsets[t + 1]; ++k) {
      const Eigen::Vector3d& a = r.plan.points[r.point_ids[k]].direction;
      if (a == Eigen::Vector3d::Zero()) continue;
      const double c = normals[t].cast<double>().dot(a);
      scale[k] = std::abs(c) >= kMinCosine ? static_cast<float>(1 / c) : NAN;
    }
  return scale;
}

// Each section: a name, a finite plane that crosses the part (vertices on
// both sides), a width > 0, an existing region, a band and a fraction.
absl::Status CheckSections(const InspectionPlan& plan, const TriangleMesh& part,
                           const std::string& where, std::set<std::string>& names) {
  for (std::size_t i = 0; i < plan.sections.size(); ++i) {
    const PlanSection& s = plan.sections[i];
    const std::string path = Index(where + ".sections", i);
    RETURN_IF_ERROR(CheckName(path + ".name", s.name, names));
    if (!s.point_mm.allFinite()) return Bad(path + ".point_mm", "not a finite number");
    if (!s.normal.allFinite() || !(s.normal.norm() > 0))
      return Bad(path + ".normal", "must be a finite non-zero vector");
    RETURN_IF_ERROR(CheckFinite(path + ".width_mm", s.width_mm));
    if (!(s.width_mm > 0)) return Bad(path + ".width_mm", "must be > 0");
    double lo = INFINITY, hi = -INFINITY;
    for (const Eigen::Vector3f& v : part.vertices) {
      const double d = (v.cast<double>() - s.point_mm).dot(s.normal.normalized());
      lo = std::min(lo, d), hi = std::max(hi, d);
    }
    if (!(lo <= 0 && hi >= 0)) return Bad(path, "the plane misses the part");
    bool known = s.region.empty();
    for (const PlanRegion& r : plan.regions) known |= r.name == s.region;
    if (!known) return Bad(path + ".region", absl::StrCat("no region \"", s.region, "\""));
    if (s.tolerance) RETURN_IF_ERROR(CheckBand(path + ".tolerance_mm", *s.tolerance));
    RETURN_IF_ERROR(CheckFraction(path + ".allowed_fraction_outside", s.allowed_fraction_outside));
  }
  return absl::OkStatus();
}

// A hole's path names it as the JSON does: the k-th of its kind.
std::string HolePath(const InspectionPlan& plan, const std::string& where, std::size_t k) {
  std::size_t same = 0;
  for (std::size_t i = 0; i < k; ++i) same += plan.holes[i].slot == plan.holes[k].slot;
  return Index(where + (plan.holes[k].slot ? ".slots" : ".holes"), same);
}

absl::Status CheckHole(const PlanHole& h, const std::string& path) {
  if (!h.position_mm.allFinite()) return Bad(path + ".position_mm", "not a finite number");
  if (!h.axis.allFinite() || !(h.axis.norm() > 0))
    return Bad(path + ".axis", "must be a finite non-zero vector");
  const char* size = h.slot ? ".width_mm" : ".diameter_mm";
  RETURN_IF_ERROR(CheckFinite(path + size, h.diameter_mm));
  if (!(h.diameter_mm > 0)) return Bad(path + size, "must be > 0");
  RETURN_IF_ERROR(CheckFinite(path + ".position_tolerance_mm", h.position_tolerance_mm));
  if (!(h.position_tolerance_mm > 0)) return Bad(path + ".position_tolerance_mm", "must be > 0");
  RETURN_IF_ERROR(CheckBand(path + (h.slot ? ".width_tolerance_mm" : ".diameter_tolerance_mm"),
                            h.diameter_tolerance));
  RETURN_IF_ERROR(CheckFinite(path + ".min_arc_deg", h.min_arc_deg));
  if (!(h.min_arc_deg >= 0 && h.min_arc_deg <= 360))
    return Bad(path + ".min_arc_deg", "must be in [0, 360]");
  if (!h.slot) return absl::OkStatus();
  RETURN_IF_ERROR(CheckFinite(path + ".length_mm", h.length_mm));
  if (!(h.length_mm > h.diameter_mm)) return Bad(path + ".length_mm", "must be > width_mm");
  RETURN_IF_ERROR(CheckBand(path + ".length_tolerance_mm", h.length_tolerance));
  const Eigen::Vector3d a = h.axis.normalized();
  if (!h.direction.allFinite() ||
      !((h.direction - h.direction.dot(a) * a).norm() > 0.1 * h.direction.norm()))
    return Bad(path + ".direction", "must be a finite vector across the axis");
  return absl::OkStatus();
}

// Each hole must have a nominal one in the CAD: a hole the CAD lists
// (core/plan/cad_holes.h) whose edge encloses the plan's position.
absl::Status CheckHoles(const InspectionPlan& plan, const TriangleMesh& part,
                        const std::string& where, std::set<std::string>& names) {
  if (plan.holes.empty()) return absl::OkStatus();
  const std::vector<CadHole> cad = ListHoles(part);
  for (std::size_t k = 0; k < plan.holes.size(); ++k) {
    const PlanHole& h = plan.holes[k];
    const std::string path = HolePath(plan, where, k);
    RETURN_IF_ERROR(CheckName(path + ".name", h.name, names));
    RETURN_IF_ERROR(CheckHole(h, path));
    bool near = false;
    for (const CadHole& c : cad)
      near |= (c.position_mm - h.position_mm).norm() <= 0.5 * c.diameter_mm;
    if (!near)
      return Bad(path + ".position_mm",
                 absl::StrCat("no hole of the CAD there (", cad.size(),
                              " found: boundary loops or solid rims that are circles or slots)"));
  }
  return absl::OkStatus();
}

// An edge point needs a CAD boundary within its radius.
absl::Status CheckEdgePoints(const InspectionPlan& plan, const TriangleMesh& part,
                             const std::string& where, std::set<std::string>& names) {
  for (std::size_t k = 0; k < plan.edge_points.size(); ++k) {
    const PlanEdgePoint& e = plan.edge_points[k];
    const std::string path = Index(where + ".edge_points", k);
    RETURN_IF_ERROR(CheckName(path + ".name", e.name, names));
    if (!e.position_mm.allFinite()) return Bad(path + ".position_mm", "not a finite number");
    RETURN_IF_ERROR(CheckFinite(path + ".radius_mm", e.radius_mm));
    if (!(e.radius_mm > 0)) return Bad(path + ".radius_mm", "must be > 0");
    RETURN_IF_ERROR(CheckBand(path + ".tolerance_mm", e.tolerance));
    const std::optional<CadEdge> edge = NearestBoundaryEdge(part, e.position_mm);
    if (!edge || edge->distance_mm > e.radius_mm)
      return Bad(path + ".position_mm",
                 edge
                     ? absl::StrFormat("the CAD's boundary is %.1f mm away, farther than radius_mm",
                                       edge->distance_mm)
                     : std::string("the CAD has no boundary (a closed mesh)"));
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status ValidateInspectionPlan(const InspectionPlan& plan, const TriangleMesh& part,
                                    const MeshGroups& groups, const std::string& where) {
  if (!groups.triangle_group.empty() && groups.triangle_group.size() != part.num_triangles())
    return Bad(where, absl::StrCat("mesh groups cover ", groups.triangle_group.size(),
                                   " triangles, the part has ", part.num_triangles()));
  RETURN_IF_ERROR(CheckBand(where + ".tolerance_mm", plan.tolerance));
  if (auto st = CheckFraction(where + ".allowed_fraction_outside", plan.allowed_fraction_outside);
      !st.ok())
    return st;
  RETURN_IF_ERROR(CheckFraction(where + ".min_coverage", plan.min_coverage));
  RETURN_IF_ERROR(CheckFinite(where + ".coverage_distance_mm", plan.coverage_distance_mm));
  if (!(plan.coverage_distance_mm >= 0))
    return Bad(where + ".coverage_distance_mm", "must be >= 0 (0: 4 sampling spacings)");
  std::set<std::string> names;
  for (std::size_t i = 0; i < plan.regions.size(); ++i) {
    const PlanRegion& r = plan.regions[i];
    const std::string path = Index(where + ".regions", i);
    RETURN_IF_ERROR(CheckName(path + ".name", r.name, names));
    RETURN_IF_ERROR(CheckSelector(path + ".select", r.select, part, groups));
    if (r.tolerance) RETURN_IF_ERROR(CheckBand(path + ".tolerance_mm", *r.tolerance));
    if (auto st = CheckFraction(path + ".allowed_fraction_outside", r.allowed_fraction_outside);
        !st.ok())
      return st;
    if (r.min_coverage) RETURN_IF_ERROR(CheckFraction(path + ".min_coverage", *r.min_coverage));
  }
  for (std::size_t i = 0; i < plan.points.size(); ++i) {
    const ComparisonPoint& p = plan.points[i];
    const std::string path = Index(where + ".points", i);
    RETURN_IF_ERROR(CheckName(path + ".name", p.name, names));
    if (!p.position_mm.allFinite()) return Bad(path + ".position_mm", "not a finite number");
    if (!p.normal.allFinite()) return Bad(path + ".normal", "not a finite number");
    if (!p.direction.allFinite()) return Bad(path + ".direction", "not a finite number");
    RETURN_IF_ERROR(CheckFinite(path + ".radius_mm", p.radius_mm));
    if (!(p.radius_mm > 0)) return Bad(path + ".radius_mm", "must be > 0");
    if (p.tolerance) RETURN_IF_ERROR(CheckBand(path + ".tolerance_mm", *p.tolerance));
    if (p.min_coverage) RETURN_IF_ERROR(CheckFraction(path + ".min_coverage", *p.min_coverage));
  }
  RETURN_IF_ERROR(CheckSections(plan, part, where, names));
  RETURN_IF_ERROR(CheckHoles(plan, part, where, names));
  RETURN_IF_ERROR(CheckEdgePoints(plan, part, where, names));
  RETURN_IF_ERROR(ValidatePlanAlignment(plan, part, where + ".alignment"));
  if (plan.defects) {
    const std::string path = where + ".defects";
    const DefectRules& d = *plan.defects;
    RETURN_IF_ERROR(CheckFinite(path + ".threshold_mm", d.threshold_mm));
    if (!(d.threshold_mm > 0)) return Bad(path + ".threshold_mm", "must be > 0");
    RETURN_IF_ERROR(CheckFinite(path + ".min_area_mm2", d.min_area_mm2));
    if (!(d.min_area_mm2 >= 0)) return Bad(path + ".min_area_mm2", "must be >= 0");
    if (d.max_count && *d.max_count < 0) return Bad(path + ".max_count", "must be >= 0");
  }
  return absl::OkStatus();
}

absl::StatusOr<ResolvedInspectionPlan> ResolveInspectionPlan(const InspectionPlan& plan,
                                                             const TriangleMesh& part,
                                                             const MeshGroups& groups) {
  RETURN_IF_ERROR(ValidateInspectionPlan(plan, part, groups));
  ResolvedInspectionPlan r;
  r.plan = plan;
  for (PlanRegion& region : r.plan.regions)
    std::sort(region.select.triangles.begin(), region.select.triangles.end());
  const std::size_t nt = part.num_triangles();
  r.num_triangles = nt;
  std::vector<uint32_t> group_index(r.plan.regions.size(), MeshGroups::kNoGroup);
  for (std::size_t k = 0; k < r.plan.regions.size(); ++k)
    if (r.plan.regions[k].select.kind == RegionSelector::Kind::kGroup)
      group_index[k] = static_cast<uint32_t>(
          std::find(groups.names.begin(), groups.names.end(), r.plan.regions[k].select.group) -
          groups.names.begin());
  // Centroids and corners only when a region or a point asks: the default
  // plan (the whole surface) needs neither, and for a large mesh they are
  // most of this function's time.
  const bool geometry = !r.plan.regions.empty() || !r.plan.points.empty();
  std::vector<Eigen::Vector3d> centroid(geometry ? nt : 0);
  std::vector<std::array<Eigen::Vector3d, 3>> corners(geometry ? nt : 0);
  for (std::size_t t = 0; t < centroid.size(); ++t) {
    for (int c = 0; c < 3; ++c) corners[t][c] = part.vertices[part.triangles[t][c]].cast<double>();
    centroid[t] = (corners[t][0] + corners[t][1] + corners[t][2]) / 3.0;
  }
  BuildRows(
      nt, r.plan.regions.size(),
      [&](std::size_t t, std::size_t k) {
        return InRegion(r.plan.regions[k].select, static_cast<uint32_t>(t), centroid[t], groups,
                        group_index[k]);
      },
      r.region_offsets, r.region_ids);
  r.region_triangle_count.assign(r.plan.regions.size(), 0);
  for (uint32_t k : r.region_ids) ++r.region_triangle_count[k];
  // A triangle can reach a point when its closest point to the position is
  // within the radius; the bounding-sphere test first skips the far ones.
  std::vector<double> bound(r.plan.points.empty() ? 0 : nt);
  for (std::size_t t = 0; t < bound.size(); ++t)
    for (int c = 0; c < 3; ++c) bound[t] = std::max(bound[t], (corners[t][c] - centroid[t]).norm());
  BuildRows(
      nt, r.plan.points.size(),
      [&](std::size_t t, std::size_t k) {
        const ComparisonPoint& p = r.plan.points[k];
        if ((p.position_mm - centroid[t]).norm() > p.radius_mm + bound[t]) return false;
        const auto& v = corners[t];
        return ClosestPointOnTriangle(p.position_mm, v[0], v[1], v[2]).squared_distance <=
               p.radius_mm * p.radius_mm;
      },
      r.point_offsets, r.point_ids);
  r.point_scale = DirectionScales(r, part);
  return r;
}

void SelectGroupsByTriangles(InspectionPlan* plan, const MeshGroups& groups) {
  for (PlanRegion& r : plan->regions) {
    if (r.select.kind != RegionSelector::Kind::kGroup) continue;
    const auto g = static_cast<uint32_t>(
        std::find(groups.names.begin(), groups.names.end(), r.select.group) - groups.names.begin());
    r.select.kind = RegionSelector::Kind::kTriangles;
    r.select.triangles.clear();
    for (std::size_t t = 0; t < groups.triangle_group.size(); ++t)
      if (groups.Contains(static_cast<uint32_t>(t), g))
        r.select.triangles.push_back(static_cast<uint32_t>(t));
  }
}

}  // namespace surfinspect
