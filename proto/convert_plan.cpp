// proto/convert.h: the inspection plan.
#include "absl/strings/str_cat.h"
#include "core/plan/plan_alignment.h"
#include "core/types/status_macros.h"
#include "proto/convert.h"
#include "proto/convert_helpers.h"

namespace surfinspect::wire {
namespace {

absl::StatusOr<PlanRegion> RegionFromProto(const v1::PlanRegion& msg, const std::string& field) {
  PlanRegion r;
  r.name = msg.name();
  if (msg.has_tolerance_mm()) r.tolerance = BandFromProto(msg.tolerance_mm());
  if (msg.has_allowed_fraction_outside())
    r.allowed_fraction_outside = msg.allowed_fraction_outside();
  if (msg.has_min_coverage()) r.min_coverage = msg.min_coverage();
  const v1::RegionSelect& s = msg.select();
  switch (s.selector_case()) {
    case v1::RegionSelect::kBoxMm: {
      r.select.kind = RegionSelector::Kind::kBox;
      ASSIGN_OR_RETURN(auto lo,
                       Vector3FromProto(s.box_mm().min_mm(), field + ".select.box_mm.min_mm"));
      ASSIGN_OR_RETURN(auto hi,
                       Vector3FromProto(s.box_mm().max_mm(), field + ".select.box_mm.max_mm"));
      r.select.box_min_mm = lo;
      r.select.box_max_mm = hi;
      break;
    }
    case v1::RegionSelect::kTriangles:
      r.select.kind = RegionSelector::Kind::kTriangles;
      r.select.triangles.assign(s.triangles().ids().begin(), s.triangles().ids().end());
      break;
    case v1::RegionSelect::kGroup:
      r.select.kind = RegionSelector::Kind::kGroup;
      r.select.group = s.group();
      break;
    default:
      return Invalid(field + ".select", "needs exactly one selector (box_mm, triangles, group)");
  }
  return r;
}

absl::StatusOr<ComparisonPoint> PointFromProto(const v1::ComparisonPoint& msg,
                                               const std::string& field) {
  ComparisonPoint p;
  p.name = msg.name();
  ASSIGN_OR_RETURN(auto pos, Vector3FromProto(msg.position_mm(), field + ".position_mm"));
  p.position_mm = pos;
  if (msg.normal_size() != 0) {
    ASSIGN_OR_RETURN(auto n, Vector3FromProto(msg.normal(), field + ".normal"));
    if (!(n.norm() > 0) || !n.allFinite())
      return Invalid(field + ".normal", "must be a finite non-zero vector");
    p.normal = n.normalized();
  }
  if (msg.direction_size() != 0) {
    ASSIGN_OR_RETURN(auto a, Vector3FromProto(msg.direction(), field + ".direction"));
    if (!(a.norm() > 0) || !a.allFinite())
      return Invalid(field + ".direction", "must be a finite non-zero vector");
    p.direction = a.normalized();
  }
  if (msg.has_radius_mm()) p.radius_mm = msg.radius_mm();
  if (msg.has_tolerance_mm()) p.tolerance = BandFromProto(msg.tolerance_mm());
  if (msg.has_min_coverage()) p.min_coverage = msg.min_coverage();
  return p;
}

absl::StatusOr<PlanSection> SectionFromProto(const v1::PlanSection& msg, const std::string& field) {
  PlanSection s;
  s.name = msg.name();
  ASSIGN_OR_RETURN(s.point_mm, Vector3FromProto(msg.point_mm(), field + ".point_mm"));
  ASSIGN_OR_RETURN(auto n, Vector3FromProto(msg.normal(), field + ".normal"));
  if (!(n.norm() > 0) || !n.allFinite())
    return Invalid(field + ".normal", "must be a finite non-zero vector");
  s.normal = n.normalized();
  if (msg.has_width_mm()) s.width_mm = msg.width_mm();
  s.region = msg.region();
  if (msg.has_tolerance_mm()) s.tolerance = BandFromProto(msg.tolerance_mm());
  if (msg.has_allowed_fraction_outside())
    s.allowed_fraction_outside = msg.allowed_fraction_outside();
  return s;
}

absl::StatusOr<PlanHole> HoleFromProto(const v1::PlanHole& msg, const std::string& field) {
  PlanHole h;
  h.name = msg.name();
  h.slot = msg.slot();
  ASSIGN_OR_RETURN(h.position_mm, Vector3FromProto(msg.position_mm(), field + ".position_mm"));
  ASSIGN_OR_RETURN(auto a, Vector3FromProto(msg.axis(), field + ".axis"));
  if (!(a.norm() > 0) || !a.allFinite())
    return Invalid(field + ".axis", "must be a finite non-zero vector");
  h.axis = a.normalized();
  h.diameter_mm = msg.diameter_mm();
  if (msg.has_position_tolerance_mm()) h.position_tolerance_mm = msg.position_tolerance_mm();
  if (msg.has_diameter_tolerance_mm())
    h.diameter_tolerance = BandFromProto(msg.diameter_tolerance_mm());
  if (msg.has_min_arc_deg()) h.min_arc_deg = msg.min_arc_deg();
  if (!h.slot) return h;
  h.length_mm = msg.length_mm();
  ASSIGN_OR_RETURN(auto d, Vector3FromProto(msg.direction(), field + ".direction"));
  if (!(d.norm() > 0) || !d.allFinite())
    return Invalid(field + ".direction", "must be a finite non-zero vector");
  h.direction = d.normalized();
  if (msg.has_length_tolerance_mm()) h.length_tolerance = BandFromProto(msg.length_tolerance_mm());
  return h;
}

void HoleToProto(const PlanHole& h, v1::PlanHole* m) {
  m->set_name(h.name);
  m->set_slot(h.slot);
  Vector3ToProto(h.position_mm, m->mutable_position_mm());
  Vector3ToProto(h.axis, m->mutable_axis());
  m->set_diameter_mm(h.diameter_mm);
  m->set_position_tolerance_mm(h.position_tolerance_mm);
  BandToProto(h.diameter_tolerance, m->mutable_diameter_tolerance_mm());
  m->set_min_arc_deg(h.min_arc_deg);
  if (!h.slot) return;
  m->set_length_mm(h.length_mm);
  Vector3ToProto(h.direction, m->mutable_direction());
  BandToProto(h.length_tolerance, m->mutable_length_tolerance_mm());
}

absl::StatusOr<PlanAlignment> AlignmentFromProto(const v1::PlanAlignment& msg,
                                                 const std::string& field) {
  PlanAlignment a;
  switch (msg.mode()) {
    case v1::ALIGNMENT_MODE_UNSPECIFIED:
    case v1::ALIGNMENT_MODE_CALIBRATED:
      a.mode = AlignmentMode::kCalibrated;
      break;
    case v1::ALIGNMENT_MODE_RPS:
      a.mode = AlignmentMode::kRps;
      break;
    case v1::ALIGNMENT_MODE_BEST_FIT:
      a.mode = AlignmentMode::kBestFit;
      break;
    default:
      return Invalid(field + ".mode", "unknown alignment mode");
  }
  for (int i = 0; i < msg.references_size(); ++i) {
    const v1::AlignmentReference& m = msg.references(i);
    const std::string f = absl::StrCat(field, ".references[", i, "]");
    AlignmentReference r{m.name(), m.hole(), Eigen::Vector3d::Zero(), 3.0};
    if (r.hole.empty()) {
      ASSIGN_OR_RETURN(r.position_mm, Vector3FromProto(m.position_mm(), f + ".position_mm"));
    }
    if (m.has_radius_mm()) r.radius_mm = m.radius_mm();
    a.references.push_back(std::move(r));
  }
  a.regions.assign(msg.regions().begin(), msg.regions().end());
  for (int i = 0; i < msg.locked_size(); ++i)
    if (!LockDofNamed(msg.locked(i), &a.locked))
      return Invalid(absl::StrCat(field, ".locked[", i, "]"),
                     "must be one of tx, ty, tz, rx, ry, rz");
  if (msg.has_max_correction_mm()) a.max_correction_mm = msg.max_correction_mm();
  if (msg.has_max_correction_deg()) a.max_correction_deg = msg.max_correction_deg();
  return a;
}

void AlignmentToProto(const PlanAlignment& a, v1::PlanAlignment* msg) {
  const v1::AlignmentMode modes[] = {v1::ALIGNMENT_MODE_CALIBRATED, v1::ALIGNMENT_MODE_RPS,
                                     v1::ALIGNMENT_MODE_BEST_FIT};
  msg->set_mode(modes[static_cast<int>(a.mode)]);
  for (const AlignmentReference& r : a.references) {
    v1::AlignmentReference* m = msg->add_references();
    m->set_name(r.name);
    m->set_hole(r.hole);
    if (r.hole.empty()) {
      Vector3ToProto(r.position_mm, m->mutable_position_mm());
      m->set_radius_mm(r.radius_mm);
    }
  }
  for (const std::string& r : a.regions) msg->add_regions(r);
  for (int d = 0; d < kRigidDofs; ++d)
    if (a.locked.IsLocked(d)) msg->add_locked(kDofKeys[d]);
  msg->set_max_correction_mm(a.max_correction_mm);
  msg->set_max_correction_deg(a.max_correction_deg);
}

}  // namespace

absl::StatusOr<InspectionPlan> PlanFromProto(const v1::InspectionPlan& msg,
                                             const ErrorMapSettings& defaults,
                                             const std::string& field) {
  InspectionPlan plan = PlanFromSettings(defaults);
  if (msg.has_tolerance_mm()) plan.tolerance = BandFromProto(msg.tolerance_mm());
  if (msg.has_allowed_fraction_outside())
    plan.allowed_fraction_outside = msg.allowed_fraction_outside();
  plan.min_coverage = msg.has_min_coverage() ? msg.min_coverage() : kDefaultMinCoverage;
  if (msg.has_coverage_distance_mm()) plan.coverage_distance_mm = msg.coverage_distance_mm();
  plan.allow_not_measured = msg.allow_not_measured();
  for (int i = 0; i < msg.regions_size(); ++i) {
    ASSIGN_OR_RETURN(auto r,
                     RegionFromProto(msg.regions(i), absl::StrCat(field, ".regions[", i, "]")));
    plan.regions.push_back(std::move(r));
  }
  for (int i = 0; i < msg.points_size(); ++i) {
    ASSIGN_OR_RETURN(auto p,
                     PointFromProto(msg.points(i), absl::StrCat(field, ".points[", i, "]")));
    plan.points.push_back(std::move(p));
  }
  for (int i = 0; i < msg.sections_size(); ++i) {
    ASSIGN_OR_RETURN(auto s,
                     SectionFromProto(msg.sections(i), absl::StrCat(field, ".sections[", i, "]")));
    plan.sections.push_back(std::move(s));
  }
  for (int i = 0; i < msg.edge_points_size(); ++i) {
    const v1::PlanEdgePoint& m = msg.edge_points(i);
    const std::string f = absl::StrCat(field, ".edge_points[", i, "]");
    PlanEdgePoint e;
    e.name = m.name();
    ASSIGN_OR_RETURN(e.position_mm, Vector3FromProto(m.position_mm(), f + ".position_mm"));
    if (m.has_radius_mm()) e.radius_mm = m.radius_mm();
    if (m.has_tolerance_mm()) e.tolerance = BandFromProto(m.tolerance_mm());
    plan.edge_points.push_back(std::move(e));
  }
  for (int i = 0; i < msg.holes_size(); ++i) {
    ASSIGN_OR_RETURN(auto h, HoleFromProto(msg.holes(i), absl::StrCat(field, ".holes[", i, "]")));
    plan.holes.push_back(std::move(h));
  }
  if (msg.has_defects()) {
    DefectRules d;
    const v1::DefectRules& m = msg.defects();
    if (m.has_threshold_mm()) d.threshold_mm = m.threshold_mm();
    if (m.has_min_area_mm2()) d.min_area_mm2 = m.min_area_mm2();
    if (m.has_max_count()) d.max_count = m.max_count();
    plan.defects = d;
  }
  if (msg.has_alignment()) {
    ASSIGN_OR_RETURN(plan.alignment, AlignmentFromProto(msg.alignment(), field + ".alignment"));
  }
  return plan;
}

void PlanToProto(const InspectionPlan& plan, v1::InspectionPlan* msg) {
  msg->Clear();
  BandToProto(plan.tolerance, msg->mutable_tolerance_mm());
  msg->set_allowed_fraction_outside(plan.allowed_fraction_outside);
  msg->set_min_coverage(plan.min_coverage);
  msg->set_coverage_distance_mm(plan.coverage_distance_mm);
  msg->set_allow_not_measured(plan.allow_not_measured);
  for (const PlanRegion& r : plan.regions) {
    v1::PlanRegion* m = msg->add_regions();
    m->set_name(r.name);
    if (r.tolerance) BandToProto(*r.tolerance, m->mutable_tolerance_mm());
    m->set_allowed_fraction_outside(r.allowed_fraction_outside);
    if (r.min_coverage) m->set_min_coverage(*r.min_coverage);
    v1::RegionSelect* s = m->mutable_select();
    switch (r.select.kind) {
      case RegionSelector::Kind::kBox:
        Vector3ToProto(r.select.box_min_mm, s->mutable_box_mm()->mutable_min_mm());
        Vector3ToProto(r.select.box_max_mm, s->mutable_box_mm()->mutable_max_mm());
        break;
      case RegionSelector::Kind::kTriangles:
        for (uint32_t t : r.select.triangles) s->mutable_triangles()->add_ids(t);
        s->mutable_triangles();  // an empty list is still this selector
        break;
      case RegionSelector::Kind::kGroup:
        s->set_group(r.select.group);
        break;
    }
  }
  for (const ComparisonPoint& p : plan.points) {
    v1::ComparisonPoint* m = msg->add_points();
    m->set_name(p.name);
    Vector3ToProto(p.position_mm, m->mutable_position_mm());
    if (p.normal != Eigen::Vector3d::Zero()) Vector3ToProto(p.normal, m->mutable_normal());
    if (p.direction != Eigen::Vector3d::Zero()) Vector3ToProto(p.direction, m->mutable_direction());
    m->set_radius_mm(p.radius_mm);
    if (p.tolerance) BandToProto(*p.tolerance, m->mutable_tolerance_mm());
    if (p.min_coverage) m->set_min_coverage(*p.min_coverage);
  }
  for (const PlanSection& s : plan.sections) {
    v1::PlanSection* m = msg->add_sections();
    m->set_name(s.name);
    Vector3ToProto(s.point_mm, m->mutable_point_mm());
    Vector3ToProto(s.normal, m->mutable_normal());
    m->set_width_mm(s.width_mm);
    m->set_region(s.region);
    if (s.tolerance) BandToProto(*s.tolerance, m->mutable_tolerance_mm());
    m->set_allowed_fraction_outside(s.allowed_fraction_outside);
  }
  for (const PlanHole& h : plan.holes) HoleToProto(h, msg->add_holes());
  for (const PlanEdgePoint& e : plan.edge_points) {
    v1::PlanEdgePoint* m = msg->add_edge_points();
    m->set_name(e.name);
    Vector3ToProto(e.position_mm, m->mutable_position_mm());
    m->set_radius_mm(e.radius_mm);
    BandToProto(e.tolerance, m->mutable_tolerance_mm());
  }
  if (plan.defects) {
    v1::DefectRules* d = msg->mutable_defects();
    d->set_threshold_mm(plan.defects->threshold_mm);
    d->set_min_area_mm2(plan.defects->min_area_mm2);
    if (plan.defects->max_count) d->set_max_count(*plan.defects->max_count);
  }
  if (plan.alignment.mode != AlignmentMode::kCalibrated)
    AlignmentToProto(plan.alignment, msg->mutable_alignment());
}

}  // namespace surfinspect::wire
