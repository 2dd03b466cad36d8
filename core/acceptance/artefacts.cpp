#include "core/acceptance/artefacts.h"

#include <cmath>
#include <set>

#include "absl/strings/str_cat.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

using json = nlohmann::json;

json Vec(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

json ViewJson(const ArtefactView& v) { return {{"view", v.view}, {"centre_mm", Vec(v.centre_mm)}}; }

// Reads j[key] as T; a missing key or a wrong type names the field.
template <typename T>
absl::Status Get(const json& j, const std::string& key, const std::string& where, T* out) {
  if (!j.is_object() || !j.contains(key))
    return absl::InvalidArgumentError(absl::StrCat(where, ".", key, ": missing"));
  try {
    *out = j.at(key).get<T>();
  } catch (const json::exception&) {
    return absl::InvalidArgumentError(absl::StrCat(where, ".", key, ": wrong type"));
  }
  return absl::OkStatus();
}

absl::Status GetVec(const json& j, const std::string& key, const std::string& where,
                    Eigen::Vector3d* out) {
  std::vector<double> v;
  RETURN_IF_ERROR(Get(j, key, where, &v));
  if (v.size() != 3 || !std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
    return absl::InvalidArgumentError(absl::StrCat(where, ".", key, ": three finite numbers"));
  *out = {v[0], v[1], v[2]};
  return absl::OkStatus();
}

absl::Status GetView(const json& j, const std::string& where, ArtefactView* v) {
  RETURN_IF_ERROR(Get(j, "view", where, &v->view));
  return GetVec(j, "centre_mm", where, &v->centre_mm);
}

absl::Status ParseMeasurements(const json& j, const std::string& src, Artefacts* a) {
  const json& s = j.value("sphere", json::object());
  const json& b = j.value("ball_bar", json::object());
  const json& p = j.value("plate", json::object());
  for (const json& m : s.value("measurements", json::array())) {
    SphereMeasurement sm;
    const std::string where = src + ": sphere.measurements[]";
    RETURN_IF_ERROR(Get(m, "name", where, &sm.name));
    RETURN_IF_ERROR(GetView(m, where, &sm.at));
    a->spheres.push_back(sm);
  }
  for (const json& m : b.value("positions", json::array())) {
    BallBarPosition bp;
    const std::string where = src + ": ball_bar.positions[]";
    RETURN_IF_ERROR(Get(m, "name", where, &bp.name));
    RETURN_IF_ERROR(GetView(m.value("a", json::object()), where + ".a", &bp.a));
    RETURN_IF_ERROR(GetView(m.value("b", json::object()), where + ".b", &bp.b));
    a->ball_bar.push_back(bp);
  }
  for (const json& m : p.value("measurements", json::array())) {
    PlateMeasurement pm;
    const std::string where = src + ": plate.measurements[]";
    RETURN_IF_ERROR(Get(m, "name", where, &pm.name));
    RETURN_IF_ERROR(GetView(m, where, &pm.at));
    RETURN_IF_ERROR(GetVec(m, "normal", where, &pm.normal));
    RETURN_IF_ERROR(Get(m, "radius_mm", where, &pm.radius_mm));
    if (pm.normal.norm() > 0) pm.normal.normalize();
    a->plates.push_back(pm);
  }
  return absl::OkStatus();
}

absl::Status ParseScalars(const json& j, const std::string& src, Artefacts* a) {
  const json& s = j.value("sphere", json::object());
  const json& b = j.value("ball_bar", json::object());
  const json& p = j.value("plate", json::object());
  const json& m = j.value("mpe_mm", json::object());
  for (auto [obj, key, where, out] :
       {std::tuple{&s, "diameter_mm", "sphere", &a->sphere_diameter_mm},
        {&s, "u_diameter_mm", "sphere", &a->sphere_diameter_u_mm},
        {&b, "length_mm", "ball_bar", &a->ball_bar_length_mm},
        {&b, "u_length_mm", "ball_bar", &a->ball_bar_length_u_mm},
        {&b, "sphere_diameter_mm", "ball_bar", &a->ball_bar_sphere_diameter_mm},
        {&p, "u_flatness_mm", "plate", &a->plate_flatness_u_mm},
        {&m, "PF", "mpe_mm", &a->mpe.pf_mm},
        {&m, "PS", "mpe_mm", &a->mpe.ps_mm},
        {&m, "SD", "mpe_mm", &a->mpe.sd_mm},
        {&m, "F", "mpe_mm", &a->mpe.f_mm}})
    RETURN_IF_ERROR(Get(*obj, key, absl::StrCat(src, ": ", where), out));
  a->search_mm = j.value("search_mm", a->search_mm);
  a->band_mm = j.value("band_mm", a->band_mm);
  a->outlier_share = j.value("outlier_share", a->outlier_share);
  return absl::OkStatus();
}

}  // namespace

absl::Status ValidateArtefacts(const Artefacts& a, const std::string& src) {
  const auto bad = [&](const std::string& field, const std::string& why) {
    return absl::InvalidArgumentError(absl::StrCat(src, ": ", field, ": ", why));
  };
  if (!(a.sphere_diameter_mm > 0)) return bad("sphere.diameter_mm", "must be > 0");
  if (!(a.ball_bar_length_mm > 0)) return bad("ball_bar.length_mm", "must be > 0");
  if (!(a.ball_bar_sphere_diameter_mm > 0))
    return bad("ball_bar.sphere_diameter_mm", "must be > 0");
  for (auto [v, f] : {std::pair{a.sphere_diameter_u_mm, "sphere.u_diameter_mm"},
                      {a.ball_bar_length_u_mm, "ball_bar.u_length_mm"},
                      {a.plate_flatness_u_mm, "plate.u_flatness_mm"},
                      {a.mpe.pf_mm, "mpe_mm.PF"},
                      {a.mpe.ps_mm, "mpe_mm.PS"},
                      {a.mpe.sd_mm, "mpe_mm.SD"},
                      {a.mpe.f_mm, "mpe_mm.F"}})
    if (!(v >= 0) || !std::isfinite(v)) return bad(f, "must be a finite number >= 0");
  if (!(a.search_mm > 0 && a.band_mm > 0)) return bad("search_mm/band_mm", "must be > 0");
  if (!(a.outlier_share >= 0 && a.outlier_share < 0.05))
    return bad("outlier_share", "in [0, 0.05)");
  if (a.spheres.empty()) return bad("sphere.measurements", "at least one");
  if (a.ball_bar.empty()) return bad("ball_bar.positions", "at least one");
  if (a.plates.empty()) return bad("plate.measurements", "at least one");
  std::set<std::string> names;
  auto unique = [&](const std::string& n) { return !n.empty() && names.insert(n).second; };
  for (const auto& s : a.spheres)
    if (!unique(s.name)) return bad("sphere.measurements", "empty or repeated name " + s.name);
  for (const auto& b : a.ball_bar)
    if (!unique(b.name)) return bad("ball_bar.positions", "empty or repeated name " + b.name);
  for (const auto& p : a.plates) {
    if (!unique(p.name)) return bad("plate.measurements", "empty or repeated name " + p.name);
    if (!(std::abs(p.normal.norm() - 1) < 1e-9)) return bad(p.name + ".normal", "must be non-zero");
    if (!(p.radius_mm > 0)) return bad(p.name + ".radius_mm", "must be > 0");
  }
  return absl::OkStatus();
}

absl::StatusOr<Artefacts> ArtefactsFromJson(const json& j, const std::string& src) {
  if (!j.is_object()) return absl::InvalidArgumentError(src + ": not a JSON object");
  if (j.value("schema", "") != "surfinspect.artefacts/1")
    return absl::InvalidArgumentError(src + ": schema: expected \"surfinspect.artefacts/1\"");
  Artefacts a;
  try {
    RETURN_IF_ERROR(ParseScalars(j, src, &a));
    RETURN_IF_ERROR(ParseMeasurements(j, src, &a));
  } catch (const json::exception& e) {
    return absl::InvalidArgumentError(absl::StrCat(src, ": ", e.what()));
  }
  RETURN_IF_ERROR(ValidateArtefacts(a, src));
  return a;
}

json ArtefactsToJson(const Artefacts& a) {
  json spheres = json::array(), positions = json::array(), plates = json::array();
  for (const auto& s : a.spheres) {
    json m = ViewJson(s.at);
    m["name"] = s.name;
    spheres.push_back(m);
  }
  for (const auto& b : a.ball_bar)
    positions.push_back({{"name", b.name}, {"a", ViewJson(b.a)}, {"b", ViewJson(b.b)}});
  for (const auto& p : a.plates) {
    json m = ViewJson(p.at);
    m["name"] = p.name;
    m["normal"] = Vec(p.normal);
    m["radius_mm"] = p.radius_mm;
    plates.push_back(m);
  }
  return {{"schema", "surfinspect.artefacts/1"},
          {"sphere",
           {{"diameter_mm", a.sphere_diameter_mm},
            {"u_diameter_mm", a.sphere_diameter_u_mm},
            {"measurements", spheres}}},
          {"ball_bar",
           {{"length_mm", a.ball_bar_length_mm},
            {"u_length_mm", a.ball_bar_length_u_mm},
            {"sphere_diameter_mm", a.ball_bar_sphere_diameter_mm},
            {"positions", positions}}},
          {"plate", {{"u_flatness_mm", a.plate_flatness_u_mm}, {"measurements", plates}}},
          {"mpe_mm",
           {{"PF", a.mpe.pf_mm}, {"PS", a.mpe.ps_mm}, {"SD", a.mpe.sd_mm}, {"F", a.mpe.f_mm}}},
          {"search_mm", a.search_mm},
          {"band_mm", a.band_mm},
          {"outlier_share", a.outlier_share}};
}

}  // namespace surfinspect
