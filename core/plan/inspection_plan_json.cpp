// The JSON form of the inspection plan (docs/inspection-plan.md): keys and
// types are checked here, naming the field; the values then go through
// ValidateInspectionPlan like a plan from any other source.
#include <cmath>
#include <initializer_list>
#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"
#include "core/plan/inspection_plan.h"
#include "core/plan/plan_alignment.h"
#include "core/plan/plan_json_read.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

using nlohmann::json;
using namespace plan_json;  // NOLINT: the plan's JSON reading helpers

absl::StatusOr<ToleranceBand> Band(const json& j, const std::string& path) {
  if (auto st = CheckKeys(j, path, {"lower", "upper"}); !st.ok()) return st;
  if (!j.contains("lower") || !j.contains("upper")) return Bad(path, "needs lower and upper");
  ToleranceBand b;
  ASSIGN_OR_RETURN(auto lo, Number(j["lower"], path + ".lower"));
  ASSIGN_OR_RETURN(auto hi, Number(j["upper"], path + ".upper"));
  b.lower_mm = lo;
  b.upper_mm = hi;
  return b;
}

absl::StatusOr<RegionSelector> Selector(const json& j, const std::string& path) {
  if (auto st = CheckKeys(j, path, {"box_mm", "triangles", "group"}); !st.ok()) return st;
  if (j.size() != 1) return Bad(path, "needs exactly one of box_mm, triangles, group");
  RegionSelector s;
  if (j.contains("box_mm")) {
    const json& b = j["box_mm"];
    const std::string p = path + ".box_mm";
    if (!b.is_array() || b.size() != 2)
      return Bad(p, "must be [[xmin, ymin, zmin], [xmax, ymax, zmax]]");
    ASSIGN_OR_RETURN(auto lo, Vector3(b[0], Index(p, 0)));
    ASSIGN_OR_RETURN(auto hi, Vector3(b[1], Index(p, 1)));
    s.box_min_mm = lo;
    s.box_max_mm = hi;
  } else if (j.contains("triangles")) {
    s.kind = RegionSelector::Kind::kTriangles;
    const json& t = j["triangles"];
    const std::string p = path + ".triangles";
    if (!t.is_array()) return Bad(p, "must be an array of triangle ids");
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (!t[i].is_number_integer() || t[i].get<int64_t>() < 0 ||
          t[i].get<int64_t>() > int64_t{UINT32_MAX - 1})
        return Bad(Index(p, i), "triangle id must be an integer in [0, 2^32 - 2]");
      s.triangles.push_back(static_cast<uint32_t>(t[i].get<int64_t>()));
    }
  } else {
    s.kind = RegionSelector::Kind::kGroup;
    ASSIGN_OR_RETURN(auto g, String(j["group"], path + ".group"));
    s.group = g;
  }
  return s;
}

absl::StatusOr<PlanRegion> Region(const json& j, const std::string& path) {
  if (auto st = CheckKeys(
          j, path, {"name", "select", "tolerance_mm", "allowed_fraction_outside", "min_coverage"});
      !st.ok())
    return st;
  PlanRegion r;
  if (!j.contains("name")) return Bad(path + ".name", "missing");
  ASSIGN_OR_RETURN(auto name, String(j["name"], path + ".name"));
  r.name = name;
  if (!j.contains("select")) return Bad(path + ".select", "missing");
  ASSIGN_OR_RETURN(r.select, Selector(j["select"], path + ".select"));
  if (j.contains("tolerance_mm")) {
    ASSIGN_OR_RETURN(auto b, Band(j["tolerance_mm"], path + ".tolerance_mm"));
    r.tolerance = b;
  }
  if (j.contains("allowed_fraction_outside")) {
    ASSIGN_OR_RETURN(auto f,
                     Number(j["allowed_fraction_outside"], path + ".allowed_fraction_outside"));
    r.allowed_fraction_outside = f;
  }
  RETURN_IF_ERROR(OptionalNumber(j, "min_coverage", path, r.min_coverage));
  return r;
}

absl::StatusOr<ComparisonPoint> Point(const json& j, const std::string& path) {
  if (auto st = CheckKeys(j, path,
                          {"name", "position_mm", "normal", "direction", "radius_mm",
                           "tolerance_mm", "min_coverage"});
      !st.ok())
    return st;
  ComparisonPoint p;
  if (!j.contains("name")) return Bad(path + ".name", "missing");
  ASSIGN_OR_RETURN(auto name, String(j["name"], path + ".name"));
  p.name = name;
  if (!j.contains("position_mm")) return Bad(path + ".position_mm", "missing");
  ASSIGN_OR_RETURN(auto pos, Vector3(j["position_mm"], path + ".position_mm"));
  p.position_mm = pos;
  if (j.contains("normal")) {
    ASSIGN_OR_RETURN(auto n, Vector3(j["normal"], path + ".normal"));
    if (!(n.norm() > 1e-12)) return Bad(path + ".normal", "zero vector");
    p.normal = n.normalized();
  }
  if (j.contains("direction")) {
    ASSIGN_OR_RETURN(auto a, Vector3(j["direction"], path + ".direction"));
    if (!(a.norm() > 1e-12)) return Bad(path + ".direction", "zero vector");
    p.direction = a.normalized();
  }
  if (j.contains("radius_mm")) {
    ASSIGN_OR_RETURN(auto r, Number(j["radius_mm"], path + ".radius_mm"));
    p.radius_mm = r;
  }
  if (j.contains("tolerance_mm")) {
    ASSIGN_OR_RETURN(auto b, Band(j["tolerance_mm"], path + ".tolerance_mm"));
    p.tolerance = b;
  }
  RETURN_IF_ERROR(OptionalNumber(j, "min_coverage", path, p.min_coverage));
  return p;
}

absl::StatusOr<PlanSection> Section(const json& j, const std::string& path) {
  if (auto st = CheckKeys(j, path,
                          {"name", "point_mm", "normal", "width_mm", "region", "tolerance_mm",
                           "allowed_fraction_outside"});
      !st.ok())
    return st;
  PlanSection s;
  for (const char* key : {"name", "point_mm", "normal"})
    if (!j.contains(key)) return Bad(absl::StrCat(path, ".", key), "missing");
  ASSIGN_OR_RETURN(s.name, String(j["name"], path + ".name"));
  ASSIGN_OR_RETURN(s.point_mm, Vector3(j["point_mm"], path + ".point_mm"));
  ASSIGN_OR_RETURN(auto n, Vector3(j["normal"], path + ".normal"));
  if (!(n.norm() > 1e-12)) return Bad(path + ".normal", "zero vector");
  s.normal = n.normalized();
  RETURN_IF_ERROR(OptionalNumber(j, "width_mm", path, s.width_mm));
  if (j.contains("region")) {
    ASSIGN_OR_RETURN(s.region, String(j["region"], path + ".region"));
  }
  if (j.contains("tolerance_mm")) {
    ASSIGN_OR_RETURN(auto b, Band(j["tolerance_mm"], path + ".tolerance_mm"));
    s.tolerance = b;
  }
  RETURN_IF_ERROR(OptionalNumber(j, "allowed_fraction_outside", path, s.allowed_fraction_outside));
  return s;
}

// The keys a hole and a slot share; `size` is "diameter" or "width".
absl::Status HoleCommon(const json& j, const std::string& path, const char* size, PlanHole& h) {
  const std::string size_key = absl::StrCat(size, "_mm"),
                    band_key = absl::StrCat(size, "_tolerance_mm");
  for (const std::string& key :
       {std::string("name"), std::string("position_mm"), std::string("axis"), size_key})
    if (!j.contains(key)) return Bad(absl::StrCat(path, ".", key), "missing");
  ASSIGN_OR_RETURN(h.name, String(j["name"], path + ".name"));
  ASSIGN_OR_RETURN(h.position_mm, Vector3(j["position_mm"], path + ".position_mm"));
  ASSIGN_OR_RETURN(h.axis, UnitVector(j["axis"], path + ".axis"));
  ASSIGN_OR_RETURN(h.diameter_mm, Number(j[size_key], absl::StrCat(path, ".", size_key)));
  RETURN_IF_ERROR(OptionalNumber(j, "position_tolerance_mm", path, h.position_tolerance_mm));
  if (j.contains(band_key)) {
    ASSIGN_OR_RETURN(h.diameter_tolerance, Band(j[band_key], absl::StrCat(path, ".", band_key)));
  }
  return OptionalNumber(j, "min_arc_deg", path, h.min_arc_deg);
}

absl::StatusOr<PlanHole> Hole(const json& j, const std::string& path) {
  RETURN_IF_ERROR(CheckKeys(j, path,
                            {"name", "position_mm", "axis", "diameter_mm", "position_tolerance_mm",
                             "diameter_tolerance_mm", "min_arc_deg"}));
  PlanHole h;
  RETURN_IF_ERROR(HoleCommon(j, path, "diameter", h));
  return h;
}

absl::StatusOr<PlanHole> Slot(const json& j, const std::string& path) {
  RETURN_IF_ERROR(CheckKeys(
      j, path,
      {"name", "position_mm", "axis", "direction", "width_mm", "length_mm", "position_tolerance_mm",
       "width_tolerance_mm", "length_tolerance_mm", "min_arc_deg"}));
  PlanHole h;
  h.slot = true;
  RETURN_IF_ERROR(HoleCommon(j, path, "width", h));
  for (const char* key : {"direction", "length_mm"})
    if (!j.contains(key)) return Bad(absl::StrCat(path, ".", key), "missing");
  ASSIGN_OR_RETURN(h.direction, UnitVector(j["direction"], path + ".direction"));
  ASSIGN_OR_RETURN(h.length_mm, Number(j["length_mm"], path + ".length_mm"));
  if (j.contains("length_tolerance_mm")) {
    ASSIGN_OR_RETURN(h.length_tolerance,
                     Band(j["length_tolerance_mm"], path + ".length_tolerance_mm"));
  }
  return h;
}

absl::StatusOr<PlanEdgePoint> EdgePoint(const json& j, const std::string& path) {
  RETURN_IF_ERROR(CheckKeys(j, path, {"name", "position_mm", "radius_mm", "tolerance_mm"}));
  PlanEdgePoint e;
  for (const char* key : {"name", "position_mm"})
    if (!j.contains(key)) return Bad(absl::StrCat(path, ".", key), "missing");
  ASSIGN_OR_RETURN(e.name, String(j["name"], path + ".name"));
  ASSIGN_OR_RETURN(e.position_mm, Vector3(j["position_mm"], path + ".position_mm"));
  RETURN_IF_ERROR(OptionalNumber(j, "radius_mm", path, e.radius_mm));
  if (j.contains("tolerance_mm")) {
    ASSIGN_OR_RETURN(e.tolerance, Band(j["tolerance_mm"], path + ".tolerance_mm"));
  }
  return e;
}

absl::StatusOr<DefectRules> Defects(const json& j, const std::string& path) {
  if (auto st = CheckKeys(j, path, {"threshold_mm", "min_area_mm2", "max_count"}); !st.ok())
    return st;
  DefectRules d;
  if (j.contains("threshold_mm")) {
    ASSIGN_OR_RETURN(auto v, Number(j["threshold_mm"], path + ".threshold_mm"));
    d.threshold_mm = v;
  }
  if (j.contains("min_area_mm2")) {
    ASSIGN_OR_RETURN(auto v, Number(j["min_area_mm2"], path + ".min_area_mm2"));
    d.min_area_mm2 = v;
  }
  if (j.contains("max_count")) {
    const json& m = j["max_count"];
    if (!m.is_number_integer() || m.get<int64_t>() < 0 || m.get<int64_t>() > 1000000)
      return Bad(path + ".max_count", "must be an integer in [0, 1000000]");
    d.max_count = static_cast<int>(m.get<int64_t>());
  }
  return d;
}

}  // namespace

absl::StatusOr<InspectionPlan> ParseInspectionPlan(const json& j, const TriangleMesh& part,
                                                   const std::string& where,
                                                   const MeshGroups& groups) {
  if (auto st = CheckKeys(j, where,
                          {"schema", "tolerance_mm", "allowed_fraction_outside", "min_coverage",
                           "coverage_distance_mm", "allow_not_measured", "regions", "points",
                           "sections", "holes", "slots", "edge_points", "defects", "alignment"});
      !st.ok())
    return st;
  InspectionPlan plan;
  if (j.contains("schema")) {
    ASSIGN_OR_RETURN(auto s, String(j["schema"], where + ".schema"));
    if (s != kInspectionPlanSchema)
      return Bad(where + ".schema", absl::StrCat("unsupported \"", s, "\" (this version reads \"",
                                                 kInspectionPlanSchema, "\")"));
  }
  if (j.contains("tolerance_mm")) {
    ASSIGN_OR_RETURN(auto b, Band(j["tolerance_mm"], where + ".tolerance_mm"));
    plan.tolerance = b;
  }
  if (j.contains("allowed_fraction_outside")) {
    ASSIGN_OR_RETURN(auto f,
                     Number(j["allowed_fraction_outside"], where + ".allowed_fraction_outside"));
    plan.allowed_fraction_outside = f;
  }
  RETURN_IF_ERROR(OptionalNumber(j, "min_coverage", where, plan.min_coverage));
  RETURN_IF_ERROR(OptionalNumber(j, "coverage_distance_mm", where, plan.coverage_distance_mm));
  if (j.contains("allow_not_measured")) {
    ASSIGN_OR_RETURN(plan.allow_not_measured,
                     Bool(j["allow_not_measured"], where + ".allow_not_measured"));
  }
  if (j.contains("regions"))
    RETURN_IF_ERROR(List(j["regions"], where + ".regions", Region, plan.regions));
  if (j.contains("points"))
    RETURN_IF_ERROR(List(j["points"], where + ".points", Point, plan.points));
  if (j.contains("sections"))
    RETURN_IF_ERROR(List(j["sections"], where + ".sections", Section, plan.sections));
  // Holes, then slots: ValidateInspectionPlan names plan.holes[k] by that order.
  if (j.contains("holes")) RETURN_IF_ERROR(List(j["holes"], where + ".holes", Hole, plan.holes));
  if (j.contains("slots")) RETURN_IF_ERROR(List(j["slots"], where + ".slots", Slot, plan.holes));
  if (j.contains("edge_points"))
    RETURN_IF_ERROR(List(j["edge_points"], where + ".edge_points", EdgePoint, plan.edge_points));
  if (j.contains("defects")) {
    ASSIGN_OR_RETURN(auto d, Defects(j["defects"], where + ".defects"));
    plan.defects = d;
  }
  if (j.contains("alignment")) {
    ASSIGN_OR_RETURN(plan.alignment, ParsePlanAlignment(j["alignment"], where + ".alignment"));
  }
  RETURN_IF_ERROR(ValidateInspectionPlan(plan, part, groups, where));
  return plan;
}

nlohmann::json PlanHolesJson(const std::vector<CadHole>& holes, double position_tolerance_mm) {
  const PlanHole defaults;
  auto vec = [](const Eigen::Vector3d& v) { return json{v.x(), v.y(), v.z()}; };
  auto band = [](const ToleranceBand& b) {
    return json{{"lower", b.lower_mm}, {"upper", b.upper_mm}};
  };
  json out = {{"holes", json::array()}, {"slots", json::array()}};
  for (const CadHole& h : holes) {
    json& list = out[h.slot ? "slots" : "holes"];
    json j = {{"name", absl::StrCat(h.slot ? "S" : "H", list.size() + 1)},
              {"position_mm", vec(h.position_mm)},
              {"axis", vec(h.axis)},
              {"position_tolerance_mm", position_tolerance_mm}};
    j[h.slot ? "width_mm" : "diameter_mm"] = h.diameter_mm;
    j[h.slot ? "width_tolerance_mm" : "diameter_tolerance_mm"] = band(defaults.diameter_tolerance);
    if (h.slot) {
      j["length_mm"] = h.length_mm;
      j["direction"] = vec(h.direction);
      j["length_tolerance_mm"] = band(defaults.length_tolerance);
    }
    list.push_back(std::move(j));
  }
  return out;
}

}  // namespace surfinspect
