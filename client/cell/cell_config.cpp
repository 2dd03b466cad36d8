#include "client/cell/cell_config.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <limits>
#include <type_traits>

#include "absl/strings/str_cat.h"
#include "core/io/atomic_file.h"
#include "core/io/io_transform.h"
#include "core/types/status_macros.h"

namespace surfinspect::client {
namespace {

absl::Status Bad(const std::string& path, absl::string_view why) {
  return absl::InvalidArgumentError(absl::StrCat(path, ": ", why));
}

std::string Resolve(const std::string& cell_path, const std::string& p) {
  if (p.empty() || p[0] == '/') return p;
  return (std::filesystem::path(cell_path).parent_path() / p).string();
}

// One entry of "viewpoints"; nlohmann::json exceptions propagate.
absl::StatusOr<CellViewpoint> ReadViewpoint(const std::string& path, const nlohmann::json& j,
                                            std::size_t i) {
  const nlohmann::json& v = j["viewpoints"][i];
  const std::string where = absl::StrCat(path, ": viewpoints[", i, "]");
  CellViewpoint vp;
  vp.name = v.at("name").get<std::string>();
  if (vp.name.empty() || vp.name.find('/') != std::string::npos)
    return Bad(where, "name must be non-empty and contain no '/'");
  if (v.contains("nominal_world_from_sensor")) {
    ASSIGN_OR_RETURN(auto t, TransformFromJsonValue(v["nominal_world_from_sensor"],
                                                    where + ".nominal_world_from_sensor"));
    vp.nominal_world_from_sensor = t;
  }
  if (v.contains("world_from_gauge")) {
    ASSIGN_OR_RETURN(auto t,
                     TransformFromJsonValue(v["world_from_gauge"], where + ".world_from_gauge"));
    vp.world_from_gauge = t;
  }
  if (v.contains("world_from_sensor") && !v["world_from_sensor"].is_null()) {
    ASSIGN_OR_RETURN(auto t,
                     TransformFromJsonValue(v["world_from_sensor"], where + ".world_from_sensor"));
    vp.world_from_sensor = t;
  }
  if (v.contains("gauge_scan")) vp.gauge_scan = Resolve(path, v["gauge_scan"].get<std::string>());
  return vp;
}

// obj[key] as a T, or `fallback` when absent. A number of the wrong kind or
// out of T's range is refused by name: nlohmann's value<T>() would wrap -5
// into an unsigned field and convert 1e300 into an int with undefined
// behaviour.
template <typename T>
absl::StatusOr<T> Number(const nlohmann::json& obj, const char* key, T fallback,
                         const std::string& where) {
  if (!obj.contains(key)) return fallback;
  const nlohmann::json& v = obj[key];
  const std::string field = absl::StrCat(where, ".", key);
  if constexpr (std::is_floating_point_v<T>) {
    if (!v.is_number() || !std::isfinite(v.get<double>()))
      return absl::InvalidArgumentError(absl::StrCat(field, " must be a finite number"));
    return v.get<T>();
  } else {
    const bool in_range =
        (v.is_number_unsigned() && v.get<uint64_t>() <= uint64_t(std::numeric_limits<T>::max())) ||
        (v.is_number_integer() && !v.is_number_unsigned() &&
         v.get<int64_t>() >= int64_t(std::numeric_limits<T>::min()) &&
         v.get<int64_t>() <= int64_t(std::numeric_limits<T>::max()));
    if (!in_range)
      return absl::InvalidArgumentError(absl::StrCat(field, " must be a whole number in [",
                                                     std::numeric_limits<T>::min(), ", ",
                                                     std::numeric_limits<T>::max(), "]"));
    return v.get<T>();
  }
}

// Reads the optional tolerance_mm, error_map{...} and filter{...} blocks.
absl::Status ReadSettings(const nlohmann::json& j, CellConfig& c) {
  ErrorMapSettings& e = c.error_map;
  LinkClusteringSettings& f = c.filter_settings;
  absl::Status st;
  auto take = [&st](auto value, auto& into) {
    if (!value.ok()) {
      if (st.ok()) st = value.status();
      return;
    }
    into = *value;
  };
  take(Number(j, "tolerance_mm", e.tolerance_mm, "cell"), e.tolerance_mm);
  if (j.contains("error_map")) {
    const auto& m = j["error_map"];
    if (!m.is_object()) return absl::InvalidArgumentError("error_map must be an object");
    take(Number(m, "max_distance_mm", e.max_distance_mm, "error_map"), e.max_distance_mm);
    take(Number(m, "allowed_fraction_outside", e.allowed_fraction_outside, "error_map"),
         e.allowed_fraction_outside);
    take(Number(m, "histogram_bins", e.histogram_bins, "error_map"), e.histogram_bins);
  }
  if (j.contains("filter")) {
    const auto& m = j["filter"];
    if (!m.is_object()) return absl::InvalidArgumentError("filter must be an object");
    c.filter = m.value("enabled", true);
    take(Number(m, "link_distance_mm", f.link_distance_mm, "filter"), f.link_distance_mm);
    take(Number(m, "min_cluster_points", f.min_cluster_points, "filter"), f.min_cluster_points);
    take(Number(m, "connectivity", f.connectivity, "filter"), f.connectivity);
  }
  return st;
}

// The "units" of `o` (a cell.json object), else `fallback`.
absl::StatusOr<InputUnit> UnitAt(const nlohmann::json& o, const std::string& where,
                                 const InputUnit& fallback) {
  if (!o.is_object() || !o.contains("units")) return fallback;
  if (!o["units"].is_string())
    return absl::InvalidArgumentError(where + ": must be a string (mm, cm, m or in)");
  const absl::StatusOr<InputUnit> u = InputUnitOf(o["units"].get<std::string>());
  if (!u.ok()) return absl::InvalidArgumentError(absl::StrCat(where, ": ", u.status().message()));
  if (!u->stated)
    return absl::InvalidArgumentError(where + ": must not be empty (mm, cm, m or in)");
  return *u;
}

// "units" for the scans and the part, "sensor.units" and "part.units" for
// each; a STEP/IGES part is read in millimetres whatever its file's unit.
absl::Status ReadUnits(const nlohmann::json& j, CellConfig& c) {
  ASSIGN_OR_RETURN(const InputUnit all, UnitAt(j, "units", InputUnit{}));
  ASSIGN_OR_RETURN(c.sensor_units, UnitAt(j.contains("sensor") ? j["sensor"] : nlohmann::json(),
                                          "sensor.units", all));
  ASSIGN_OR_RETURN(c.part_units, UnitAt(j["part"], "part.units", all));
  if (!IsCadPath(c.part_source)) return absl::OkStatus();
  if (j["part"].contains("units"))
    return absl::InvalidArgumentError(
        "part.units: a STEP/IGES part declares its own unit; it is read in millimetres");
  c.part_units = InputUnit{LengthUnit::kMillimetre, true};
  return absl::OkStatus();
}

// "cad": how a STEP/IGES part is tessellated; validated by ValidateCadSettings.
absl::Status ReadCad(const std::string& path, const nlohmann::json& j, CellConfig& c) {
  c.cad_cache = (std::filesystem::path(path).parent_path() / ".cad-cache").string();
  if (!j.contains("cad")) return absl::OkStatus();
  const nlohmann::json& m = j["cad"];
  if (!m.is_object()) return absl::InvalidArgumentError("cad must be an object");
  TessellationSettings& t = c.cad.tessellation;
  absl::Status st;
  auto take = [&st](auto value, auto& into) {
    if (value.ok())
      into = *value;
    else if (st.ok())
      st = value.status();
  };
  take(Number(m, "chord_tolerance_mm", t.chord_tolerance_mm, "cad"), t.chord_tolerance_mm);
  take(Number(m, "angular_tolerance_deg", t.angular_tolerance_deg, "cad"), t.angular_tolerance_deg);
  take(Number(m, "timeout_s", c.cad.limits.seconds, "cad"), c.cad.limits.seconds);
  take(Number(m, "memory_mb", c.cad.limits.memory_mb, "cad"), c.cad.limits.memory_mb);
  RETURN_IF_ERROR(st);
  t.body = m.value("body", "");
  if (m.contains("cache")) c.cad_cache = Resolve(path, m["cache"].get<std::string>());
  if (auto v = ValidateCadSettings(c.cad); !v.ok())
    return absl::InvalidArgumentError(absl::StrCat("cad.", v.message()));
  return absl::OkStatus();
}

// cell.json's "outputs": the catalogue names of the files each part gets
// (client/cell/part_files.h).
absl::StatusOr<PartFileSet> OutputsOf(const std::string& path, const nlohmann::json& list) {
  std::vector<std::string> names;
  if (!list.is_array())
    return Bad(path, absl::StrCat("outputs must be a list of names (", PartFileNames(), ")"));
  for (const nlohmann::json& name : list) {
    if (!name.is_string())
      return Bad(path, absl::StrCat("outputs holds a non-name: ", name.dump()));
    names.push_back(name.get<std::string>());
  }
  absl::StatusOr<PartFileSet> set = ParsePartFileSet(names, "outputs");
  if (!set.ok()) return Bad(path, set.status().message());
  return *set;
}

// The cell's name from cell.json, or the name of the folder that holds it.
absl::StatusOr<std::string> CellName(const std::string& path, const nlohmann::json& j) {
  std::string name = j.contains("name")
                         ? (j["name"].is_string() ? j["name"].get<std::string>() : std::string())
                         : std::filesystem::absolute(std::filesystem::path(path))
                               .parent_path()
                               .filename()
                               .string();
  const bool ok =
      !name.empty() && name.size() <= 64 && std::all_of(name.begin(), name.end(), [](char ch) {
        return std::isalnum(static_cast<unsigned char>(ch)) || ch == '.' || ch == '_' || ch == '-';
      });
  if (!ok)
    return Bad(path,
               absl::StrCat("name \"", name.substr(0, 64),
                            "\" must be 1-64 letters, digits, '.', '_' or '-' (set \"name\")"));
  return name;
}

}  // namespace

absl::StatusOr<CellConfig> ReadCellConfig(const std::string& path) {
  ASSIGN_OR_RETURN(auto text, ReadFileToString(path, 16 << 20));
  CellConfig c;
  c.path = path;
  c.raw = nlohmann::json::parse(text, nullptr, false);
  if (c.raw.is_discarded() || !c.raw.is_object()) return Bad(path, "not a JSON object");
  const nlohmann::json& j = c.raw;
  try {
    ASSIGN_OR_RETURN(auto name, CellName(path, j));
    c.name = std::move(name);
    if (!j.contains("part") || !j["part"].contains("mesh") ||
        !j["part"].contains("world_from_part"))
      return Bad(path, "needs part.mesh and part.world_from_part");
    c.part_mesh = c.part_source = Resolve(path, j["part"]["mesh"].get<std::string>());
    auto wfp =
        TransformFromJsonValue(j["part"]["world_from_part"], path + ": part.world_from_part");
    if (!wfp.ok()) return wfp.status();
    c.world_from_part = *wfp;
    if (j.contains("gauge") && j["gauge"].contains("mesh"))
      c.gauge_mesh = Resolve(path, j["gauge"]["mesh"].get<std::string>());
    if (!j.contains("viewpoints") || !j["viewpoints"].is_array() || j["viewpoints"].empty())
      return Bad(path, "needs a non-empty viewpoints array");
    for (std::size_t i = 0; i < j["viewpoints"].size(); ++i) {
      ASSIGN_OR_RETURN(auto vp, ReadViewpoint(path, j, i));
      c.viewpoints.push_back(std::move(vp));
    }
    if (auto st = ReadSettings(j, c); !st.ok()) return Bad(path, st.message());
    if (auto st = ReadCad(path, j, c); !st.ok()) return Bad(path, st.message());
    if (auto st = ReadUnits(j, c); !st.ok()) return Bad(path, st.message());
    if (j.contains("plan")) {
      if (j["plan"].is_string()) {
        c.plan_source = Resolve(path, j["plan"].get<std::string>());
        ASSIGN_OR_RETURN(c.plan, ReadPlanJson(c.plan_source));
      } else if (j["plan"].is_object()) {
        c.plan_source = path;
        c.plan = j["plan"];
      } else {
        return Bad(path, "plan must be a file name or an object");
      }
    }
    if (j.contains("outputs")) {
      ASSIGN_OR_RETURN(c.outputs, OutputsOf(path, j["outputs"]));
    }
    if (j.contains("server")) {
      const auto& s = j["server"];
      c.server.target = s.value("target", "");
      c.server.tls_ca = Resolve(path, s.value("tls_ca", ""));
      c.server.tls_cert = Resolve(path, s.value("tls_cert", ""));
      c.server.tls_key = Resolve(path, s.value("tls_key", ""));
      c.server.token_file = Resolve(path, s.value("token_file", ""));
    }
  } catch (const nlohmann::json::exception& e) {
    return Bad(path, absl::StrCat("malformed: ", e.what()));
  }
  if (auto st = ValidateErrorMapSettings(c.error_map); !st.ok()) return Bad(path, st.message());
  if (auto st = ValidateLinkClusteringSettings(c.filter_settings); !st.ok())
    return Bad(path, st.message());
  return c;
}

absl::StatusOr<nlohmann::json> ReadPlanJson(const std::string& path) {
  ASSIGN_OR_RETURN(auto text, ReadFileToString(path, 16 << 20));
  nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return Bad(path, "plan: not a JSON object");
  return j;
}

absl::StatusOr<std::optional<InspectionPlan>> PlanOf(const CellConfig& cell,
                                                     const TriangleMesh& part,
                                                     const ErrorMapSettings& settings) {
  if (!cell.plan) return std::optional<InspectionPlan>();
  auto plan = ParsePlanForMeshFile(*cell.plan, part, cell.part_mesh, settings, "plan",
                                   cell.part_units.unit);
  if (!plan.ok()) return Bad(cell.plan_source, plan.status().message());
  return std::optional<InspectionPlan>(*std::move(plan));
}

InspectionSettings InspectionSettingsOf(const CellConfig& cell) {
  InspectionSettings s;
  s.filter = cell.filter;
  s.filter_settings = cell.filter_settings;
  s.error_map = cell.error_map;
  return s;
}

absl::Status WriteCellCalibrations(
    const CellConfig& cell, const std::vector<std::pair<std::string, nlohmann::json>>& quality) {
  nlohmann::json j = cell.raw;
  for (auto& v : j["viewpoints"]) {
    const std::string name = v["name"].get<std::string>();
    for (const auto& vp : cell.viewpoints)
      if (vp.name == name && vp.world_from_sensor)
        v["world_from_sensor"] = TransformToJsonValue(*vp.world_from_sensor);
    for (const auto& [n, q] : quality)
      if (n == name) v["calibration"] = q;
  }
  // Keep the previous file, then replace atomically.
  ASSIGN_OR_RETURN(auto old, ReadFileToString(cell.path, 16 << 20));
  RETURN_IF_ERROR(WriteStringAtomically(cell.path + ".bak", old));
  return WriteStringAtomically(cell.path, j.dump(2) + "\n");
}

}  // namespace surfinspect::client
