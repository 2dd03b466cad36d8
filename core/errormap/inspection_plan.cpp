#include "core/errormap/inspection_plan.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <set>

#include "absl/strings/str_cat.h"
#include "core/distance/point_triangle.h"

namespace surfinspect {
namespace {

using nlohmann::json;

absl::Status Bad(const std::string& path, absl::string_view what) {
  return absl::InvalidArgumentError(absl::StrCat(path, ": ", what));
}

std::string Index(const std::string& path, std::size_t i) {
  return absl::StrCat(path, "[", i, "]");
}

// ---- validation of the struct --------------------------------------------

absl::Status CheckFinite(const std::string& path, double v) {
  return std::isfinite(v) ? absl::OkStatus() : Bad(path, "not a finite number");
}

absl::Status CheckBand(const std::string& path, const ToleranceBand& b) {
  if (auto st = CheckFinite(path + ".lower", b.lower_mm); !st.ok()) return st;
  if (auto st = CheckFinite(path + ".upper", b.upper_mm); !st.ok()) return st;
  if (b.lower_mm > b.upper_mm)
    return Bad(path, absl::StrCat("lower (", b.lower_mm, ") > upper (", b.upper_mm, ")"));
  return absl::OkStatus();
}

absl::Status CheckFraction(const std::string& path, double f) {
  if (auto st = CheckFinite(path, f); !st.ok()) return st;
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
    return Bad(path, absl::StrCat("duplicate name \"", name,
                                  "\" (regions and points share one namespace)"));
  return absl::OkStatus();
}

// ---- JSON reading ----------------------------------------------------------

absl::Status CheckKeys(const json& j, const std::string& path,
                       std::initializer_list<const char*> allowed) {
  if (!j.is_object()) return Bad(path, "must be an object");
  for (const auto& [key, value] : j.items()) {
    bool known = false;
    for (const char* a : allowed) known = known || key == a;
    if (!known) return Bad(absl::StrCat(path, ".", key), "unknown key");
  }
  return absl::OkStatus();
}

absl::StatusOr<double> Number(const json& j, const std::string& path) {
  if (!j.is_number()) return Bad(path, "must be a number");
  const double v = j.get<double>();
  if (!std::isfinite(v)) return Bad(path, "not a finite number");
  return v;
}

absl::StatusOr<Eigen::Vector3d> Vector3(const json& j, const std::string& path) {
  if (!j.is_array() || j.size() != 3) return Bad(path, "must be an array of 3 numbers");
  Eigen::Vector3d v;
  for (int a = 0; a < 3; ++a) {
    auto x = Number(j[a], Index(path, a));
    if (!x.ok()) return x.status();
    v[a] = *x;
  }
  return v;
}

absl::StatusOr<std::string> String(const json& j, const std::string& path) {
  if (!j.is_string()) return Bad(path, "must be a string");
  return j.get<std::string>();
}

absl::StatusOr<ToleranceBand> Band(const json& j, const std::string& path) {
  if (auto st = CheckKeys(j, path, {"lower", "upper"}); !st.ok()) return st;
  if (!j.contains("lower") || !j.contains("upper")) return Bad(path, "needs lower and upper");
  ToleranceBand b;
  auto lo = Number(j["lower"], path + ".lower");
  if (!lo.ok()) return lo.status();
  auto hi = Number(j["upper"], path + ".upper");
  if (!hi.ok()) return hi.status();
  b.lower_mm = *lo;
  b.upper_mm = *hi;
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
    auto lo = Vector3(b[0], Index(p, 0));
    if (!lo.ok()) return lo.status();
    auto hi = Vector3(b[1], Index(p, 1));
    if (!hi.ok()) return hi.status();
    s.box_min_mm = *lo;
    s.box_max_mm = *hi;
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
    auto g = String(j["group"], path + ".group");
    if (!g.ok()) return g.status();
    s.group = *g;
  }
  return s;
}

absl::StatusOr<PlanRegion> Region(const json& j, const std::string& path) {
  if (auto st = CheckKeys(j, path, {"name", "select", "tolerance_mm", "allowed_fraction_outside"});
      !st.ok())
    return st;
  PlanRegion r;
  if (!j.contains("name")) return Bad(path + ".name", "missing");
  auto name = String(j["name"], path + ".name");
  if (!name.ok()) return name.status();
  r.name = *name;
  if (!j.contains("select")) return Bad(path + ".select", "missing");
  auto sel = Selector(j["select"], path + ".select");
  if (!sel.ok()) return sel.status();
  r.select = *std::move(sel);
  if (j.contains("tolerance_mm")) {
    auto b = Band(j["tolerance_mm"], path + ".tolerance_mm");
    if (!b.ok()) return b.status();
    r.tolerance = *b;
  }
  if (j.contains("allowed_fraction_outside")) {
    auto f = Number(j["allowed_fraction_outside"], path + ".allowed_fraction_outside");
    if (!f.ok()) return f.status();
    r.allowed_fraction_outside = *f;
  }
  return r;
}

absl::StatusOr<ComparisonPoint> Point(const json& j, const std::string& path) {
  if (auto st = CheckKeys(j, path, {"name", "position_mm", "normal", "radius_mm", "tolerance_mm"});
      !st.ok())
    return st;
  ComparisonPoint p;
  if (!j.contains("name")) return Bad(path + ".name", "missing");
  auto name = String(j["name"], path + ".name");
  if (!name.ok()) return name.status();
  p.name = *name;
  if (!j.contains("position_mm")) return Bad(path + ".position_mm", "missing");
  auto pos = Vector3(j["position_mm"], path + ".position_mm");
  if (!pos.ok()) return pos.status();
  p.position_mm = *pos;
  if (j.contains("normal")) {
    auto n = Vector3(j["normal"], path + ".normal");
    if (!n.ok()) return n.status();
    if (!(n->norm() > 1e-12)) return Bad(path + ".normal", "zero vector");
    p.normal = n->normalized();
  }
  if (j.contains("radius_mm")) {
    auto r = Number(j["radius_mm"], path + ".radius_mm");
    if (!r.ok()) return r.status();
    p.radius_mm = *r;
  }
  if (j.contains("tolerance_mm")) {
    auto b = Band(j["tolerance_mm"], path + ".tolerance_mm");
    if (!b.ok()) return b.status();
    p.tolerance = *b;
  }
  return p;
}

absl::StatusOr<DefectRules> Defects(const json& j, const std::string& path) {
  if (auto st = CheckKeys(j, path, {"threshold_mm", "min_area_mm2", "max_count"}); !st.ok())
    return st;
  DefectRules d;
  if (j.contains("threshold_mm")) {
    auto v = Number(j["threshold_mm"], path + ".threshold_mm");
    if (!v.ok()) return v.status();
    d.threshold_mm = *v;
  }
  if (j.contains("min_area_mm2")) {
    auto v = Number(j["min_area_mm2"], path + ".min_area_mm2");
    if (!v.ok()) return v.status();
    d.min_area_mm2 = *v;
  }
  if (j.contains("max_count")) {
    const json& m = j["max_count"];
    if (!m.is_number_integer() || m.get<int64_t>() < 0 || m.get<int64_t>() > 1000000)
      return Bad(path + ".max_count", "must be an integer in [0, 1000000]");
    d.max_count = static_cast<int>(m.get<int64_t>());
  }
  return d;
}

template <typename T, typename F>
absl::Status List(const json& j, const std::string& path, F parse, std::vector<T>& out) {
  if (!j.is_array()) return Bad(path, "must be an array");
  for (std::size_t i = 0; i < j.size(); ++i) {
    auto item = parse(j[i], Index(path, i));
    if (!item.ok()) return item.status();
    out.push_back(*std::move(item));
  }
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
      return !groups.triangle_group.empty() && groups.triangle_group[t] == group_index;
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

}  // namespace

absl::Status ValidateInspectionPlan(const InspectionPlan& plan, const TriangleMesh& part,
                                    const MeshGroups& groups, const std::string& where) {
  if (!groups.triangle_group.empty() && groups.triangle_group.size() != part.num_triangles())
    return Bad(where, absl::StrCat("mesh groups cover ", groups.triangle_group.size(),
                                   " triangles, the part has ", part.num_triangles()));
  if (auto st = CheckBand(where + ".tolerance_mm", plan.tolerance); !st.ok()) return st;
  if (auto st = CheckFraction(where + ".allowed_fraction_outside", plan.allowed_fraction_outside);
      !st.ok())
    return st;
  std::set<std::string> names;
  for (std::size_t i = 0; i < plan.regions.size(); ++i) {
    const PlanRegion& r = plan.regions[i];
    const std::string path = Index(where + ".regions", i);
    if (auto st = CheckName(path + ".name", r.name, names); !st.ok()) return st;
    if (auto st = CheckSelector(path + ".select", r.select, part, groups); !st.ok()) return st;
    if (r.tolerance)
      if (auto st = CheckBand(path + ".tolerance_mm", *r.tolerance); !st.ok()) return st;
    if (auto st = CheckFraction(path + ".allowed_fraction_outside", r.allowed_fraction_outside);
        !st.ok())
      return st;
  }
  for (std::size_t i = 0; i < plan.points.size(); ++i) {
    const ComparisonPoint& p = plan.points[i];
    const std::string path = Index(where + ".points", i);
    if (auto st = CheckName(path + ".name", p.name, names); !st.ok()) return st;
    if (!p.position_mm.allFinite()) return Bad(path + ".position_mm", "not a finite number");
    if (!p.normal.allFinite()) return Bad(path + ".normal", "not a finite number");
    if (auto st = CheckFinite(path + ".radius_mm", p.radius_mm); !st.ok()) return st;
    if (!(p.radius_mm > 0)) return Bad(path + ".radius_mm", "must be > 0");
    if (p.tolerance)
      if (auto st = CheckBand(path + ".tolerance_mm", *p.tolerance); !st.ok()) return st;
  }
  if (plan.defects) {
    const std::string path = where + ".defects";
    const DefectRules& d = *plan.defects;
    if (auto st = CheckFinite(path + ".threshold_mm", d.threshold_mm); !st.ok()) return st;
    if (!(d.threshold_mm > 0)) return Bad(path + ".threshold_mm", "must be > 0");
    if (auto st = CheckFinite(path + ".min_area_mm2", d.min_area_mm2); !st.ok()) return st;
    if (!(d.min_area_mm2 >= 0)) return Bad(path + ".min_area_mm2", "must be >= 0");
    if (d.max_count && *d.max_count < 0) return Bad(path + ".max_count", "must be >= 0");
  }
  return absl::OkStatus();
}

absl::StatusOr<InspectionPlan> ParseInspectionPlan(const json& j, const TriangleMesh& part,
                                                   const std::string& where,
                                                   const MeshGroups& groups) {
  if (auto st = CheckKeys(
          j, where,
          {"schema", "tolerance_mm", "allowed_fraction_outside", "regions", "points", "defects"});
      !st.ok())
    return st;
  InspectionPlan plan;
  if (j.contains("schema")) {
    auto s = String(j["schema"], where + ".schema");
    if (!s.ok()) return s.status();
    if (*s != kInspectionPlanSchema)
      return Bad(where + ".schema", absl::StrCat("unsupported \"", *s, "\" (this version reads \"",
                                                 kInspectionPlanSchema, "\")"));
  }
  if (j.contains("tolerance_mm")) {
    auto b = Band(j["tolerance_mm"], where + ".tolerance_mm");
    if (!b.ok()) return b.status();
    plan.tolerance = *b;
  }
  if (j.contains("allowed_fraction_outside")) {
    auto f = Number(j["allowed_fraction_outside"], where + ".allowed_fraction_outside");
    if (!f.ok()) return f.status();
    plan.allowed_fraction_outside = *f;
  }
  if (j.contains("regions"))
    if (auto st = List(j["regions"], where + ".regions", Region, plan.regions); !st.ok()) return st;
  if (j.contains("points"))
    if (auto st = List(j["points"], where + ".points", Point, plan.points); !st.ok()) return st;
  if (j.contains("defects")) {
    auto d = Defects(j["defects"], where + ".defects");
    if (!d.ok()) return d.status();
    plan.defects = *d;
  }
  if (auto st = ValidateInspectionPlan(plan, part, groups, where); !st.ok()) return st;
  return plan;
}

absl::StatusOr<ResolvedInspectionPlan> ResolveInspectionPlan(const InspectionPlan& plan,
                                                             const TriangleMesh& part,
                                                             const MeshGroups& groups) {
  if (auto st = ValidateInspectionPlan(plan, part, groups); !st.ok()) return st;
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
  std::vector<Eigen::Vector3d> centroid(nt);
  std::vector<std::array<Eigen::Vector3d, 3>> corners(nt);
  for (std::size_t t = 0; t < nt; ++t) {
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
  std::vector<double> bound(nt);
  for (std::size_t t = 0; t < nt; ++t)
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
  return r;
}

}  // namespace surfinspect
