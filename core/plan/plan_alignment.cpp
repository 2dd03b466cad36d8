#include "core/plan/plan_alignment.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <set>

#include "absl/strings/str_cat.h"
#include "core/distance/point_triangle.h"
#include "core/plan/plan_json_read.h"

namespace surfinspect {

const char* const kDofKeys[kRigidDofs] = {"tx", "ty", "tz", "rx", "ry", "rz"};

bool LockDofNamed(const std::string& key, LockedDofs* locked) {
  bool* fields[kRigidDofs] = {&locked->tx, &locked->ty, &locked->tz,
                              &locked->rx, &locked->ry, &locked->rz};
  for (int d = 0; d < kRigidDofs; ++d)
    if (key == kDofKeys[d]) return *fields[d] = true;
  return false;
}

const char* AlignmentModeName(AlignmentMode mode) {
  switch (mode) {
    case AlignmentMode::kCalibrated:
      return "calibrated";
    case AlignmentMode::kRps:
      return "rps";
    case AlignmentMode::kBestFit:
      return "best_fit";
  }
  return "unknown";
}

namespace {

using nlohmann::json;
using namespace plan_json;  // NOLINT: the plan's JSON reading helpers

constexpr AlignmentMode kModes[] = {AlignmentMode::kCalibrated, AlignmentMode::kRps,
                                    AlignmentMode::kBestFit};

absl::StatusOr<AlignmentReference> Reference(const json& j, const std::string& path) {
  RETURN_IF_ERROR(CheckKeys(j, path, {"name", "hole", "position_mm", "radius_mm"}));
  AlignmentReference r;
  if (!j.contains("name")) return Bad(path + ".name", "missing");
  ASSIGN_OR_RETURN(r.name, String(j["name"], path + ".name"));
  if (j.contains("hole") == j.contains("position_mm"))
    return Bad(path, "needs exactly one of hole (a plan hole or slot) and position_mm");
  if (j.contains("hole")) {
    if (j.contains("radius_mm")) return Bad(path + ".radius_mm", "only for a surface point");
    ASSIGN_OR_RETURN(r.hole, String(j["hole"], path + ".hole"));
    return r;
  }
  ASSIGN_OR_RETURN(r.position_mm, Vector3(j["position_mm"], path + ".position_mm"));
  RETURN_IF_ERROR(OptionalNumber(j, "radius_mm", path, r.radius_mm));
  return r;
}

absl::Status Locked(const json& j, const std::string& path, LockedDofs& out) {
  if (!j.is_array()) return Bad(path, "must be an array of \"tx\" .. \"rz\"");
  for (std::size_t i = 0; i < j.size(); ++i) {
    ASSIGN_OR_RETURN(auto key, String(j[i], Index(path, i)));
    if (!LockDofNamed(key, &out))
      return Bad(Index(path, i), "must be one of tx, ty, tz, rx, ry, rz");
  }
  return absl::OkStatus();
}

// The CAD normal at the part's closest point to p (brute force: a plan
// holds a handful of references).
Eigen::Vector3d NormalAt(const TriangleMesh& part, const Eigen::Vector3d& p,
                         Eigen::Vector3d* on_cad) {
  double best = INFINITY;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  for (const auto& tri : part.triangles) {
    const Eigen::Vector3d a = part.vertices[tri[0]].cast<double>(),
                          b = part.vertices[tri[1]].cast<double>(),
                          c = part.vertices[tri[2]].cast<double>();
    const Eigen::Vector3d n = (b - a).cross(c - a);
    if (!(n.norm() > 0)) continue;
    const PointTriangleResult r = ClosestPointOnTriangle(p, a, b, c);
    if (r.squared_distance < best)
      best = r.squared_distance, normal = n.normalized(), *on_cad = r.point;
  }
  return normal;
}

}  // namespace

absl::StatusOr<PlanAlignment> ParsePlanAlignment(const json& j, const std::string& path) {
  RETURN_IF_ERROR(CheckKeys(
      j, path,
      {"mode", "references", "regions", "locked", "max_correction_mm", "max_correction_deg"}));
  PlanAlignment a;
  if (!j.contains("mode")) return Bad(path + ".mode", "missing");
  ASSIGN_OR_RETURN(auto mode, String(j["mode"], path + ".mode"));
  const auto* it = std::find_if(std::begin(kModes), std::end(kModes),
                                [&](AlignmentMode m) { return mode == AlignmentModeName(m); });
  if (it == std::end(kModes)) return Bad(path + ".mode", "must be calibrated, rps or best_fit");
  a.mode = *it;
  if (j.contains("references"))
    RETURN_IF_ERROR(List(j["references"], path + ".references", Reference, a.references));
  if (j.contains("regions"))
    RETURN_IF_ERROR(List(j["regions"], path + ".regions", String, a.regions));
  if (j.contains("locked")) RETURN_IF_ERROR(Locked(j["locked"], path + ".locked", a.locked));
  RETURN_IF_ERROR(OptionalNumber(j, "max_correction_mm", path, a.max_correction_mm));
  RETURN_IF_ERROR(OptionalNumber(j, "max_correction_deg", path, a.max_correction_deg));
  return a;
}

json PlanAlignmentJson(const PlanAlignment& a) {
  json out = {{"mode", AlignmentModeName(a.mode)},
              {"max_correction_mm", a.max_correction_mm},
              {"max_correction_deg", a.max_correction_deg}};
  for (const AlignmentReference& r : a.references) {
    json j = {{"name", r.name}};
    if (!r.hole.empty()) {
      j["hole"] = r.hole;
    } else {
      j["position_mm"] = {r.position_mm.x(), r.position_mm.y(), r.position_mm.z()};
      j["radius_mm"] = r.radius_mm;
    }
    out["references"].push_back(std::move(j));
  }
  if (!a.regions.empty()) out["regions"] = a.regions;
  for (int d = 0; d < kRigidDofs; ++d)
    if (a.locked.IsLocked(d)) out["locked"].push_back(kDofKeys[d]);
  return out;
}

absl::Status ValidatePlanAlignment(const InspectionPlan& plan, const TriangleMesh& part,
                                   const std::string& path) {
  const PlanAlignment& a = plan.alignment;
  for (const auto& [key, v] : {std::pair{".max_correction_mm", a.max_correction_mm},
                               std::pair{".max_correction_deg", a.max_correction_deg}})
    if (!(v > 0) || std::isnan(v)) return Bad(path + key, "must be > 0");
  const bool rps = a.mode == AlignmentMode::kRps, fit = a.mode == AlignmentMode::kBestFit;
  if (!rps && !a.references.empty()) return Bad(path + ".references", "only for mode rps");
  if (!fit && !a.regions.empty()) return Bad(path + ".regions", "only for mode best_fit");
  if (!fit && a.locked.FreeCount() != kRigidDofs)
    return Bad(path + ".locked", "only for mode best_fit");
  if (fit && a.locked.FreeCount() == 0)
    return Bad(path + ".locked", "locks all six degrees of freedom");
  for (std::size_t i = 0; i < a.regions.size(); ++i)
    if (std::none_of(plan.regions.begin(), plan.regions.end(),
                     [&](const PlanRegion& r) { return r.name == a.regions[i]; }))
      return Bad(Index(path + ".regions", i),
                 absl::StrCat("no region \"", a.regions[i], "\" in the plan"));
  if (!rps) return absl::OkStatus();
  if (a.references.empty()) return Bad(path + ".references", "mode rps needs references");
  std::set<std::string> names;
  for (std::size_t i = 0; i < a.references.size(); ++i) {
    const AlignmentReference& r = a.references[i];
    const std::string p = Index(path + ".references", i);
    if (r.name.empty() || !names.insert(r.name).second)
      return Bad(p + ".name", "empty or not unique");
    if (!r.hole.empty() && std::none_of(plan.holes.begin(), plan.holes.end(),
                                        [&](const PlanHole& h) { return h.name == r.hole; }))
      return Bad(p + ".hole", absl::StrCat("no hole or slot \"", r.hole, "\" in the plan"));
    if (r.hole.empty() && !r.position_mm.allFinite())
      return Bad(p + ".position_mm", "not a finite number");
    if (r.hole.empty() && !(r.radius_mm > 0 && std::isfinite(r.radius_mm)))
      return Bad(p + ".radius_mm", "must be > 0");
  }
  // The drawing's verdict on the set: solved at the nominal places, where
  // every residual is 0, so only the degeneracy analysis can refuse it.
  const auto solved = SolveRps(NominalRpsReferences(plan, part));
  if (!solved.ok()) return Bad(path + ".references", solved.status().message());
  return absl::OkStatus();
}

std::vector<RpsReference> NominalRpsReferences(const InspectionPlan& plan,
                                               const TriangleMesh& part) {
  std::vector<RpsReference> out;
  for (const AlignmentReference& r : plan.alignment.references) {
    RpsReference ref;
    ref.name = r.name;
    if (r.hole.empty()) {
      ref.directions = {NormalAt(part, r.position_mm, &ref.nominal_mm)};
    } else {
      const PlanHole& h = *std::find_if(plan.holes.begin(), plan.holes.end(),
                                        [&](const PlanHole& x) { return x.name == r.hole; });
      const PlaneFrame f = MakePlaneFrame(h.position_mm, h.axis, h.direction);
      ref.nominal_mm = h.position_mm;
      ref.directions =
          h.slot ? std::vector<Eigen::Vector3d>{f.e2} : std::vector<Eigen::Vector3d>{f.e1, f.e2};
    }
    ref.measured_mm = ref.nominal_mm;
    out.push_back(std::move(ref));
  }
  return out;
}

}  // namespace surfinspect
