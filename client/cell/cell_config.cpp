#include "client/cell/cell_config.h"

#include <filesystem>

#include "absl/strings/str_cat.h"
#include "core/io/atomic_file.h"
#include "core/io/io_transform.h"

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
    auto t = TransformFromJsonValue(v["nominal_world_from_sensor"],
                                    where + ".nominal_world_from_sensor");
    if (!t.ok()) return t.status();
    vp.nominal_world_from_sensor = *t;
  }
  if (v.contains("world_from_gauge")) {
    auto t = TransformFromJsonValue(v["world_from_gauge"], where + ".world_from_gauge");
    if (!t.ok()) return t.status();
    vp.world_from_gauge = *t;
  }
  if (v.contains("world_from_sensor") && !v["world_from_sensor"].is_null()) {
    auto t = TransformFromJsonValue(v["world_from_sensor"], where + ".world_from_sensor");
    if (!t.ok()) return t.status();
    vp.world_from_sensor = *t;
  }
  if (v.contains("gauge_scan")) vp.gauge_scan = Resolve(path, v["gauge_scan"].get<std::string>());
  return vp;
}

}  // namespace

absl::StatusOr<CellConfig> ReadCellConfig(const std::string& path) {
  auto text = ReadFileToString(path, 16 << 20);
  if (!text.ok()) return text.status();
  CellConfig c;
  c.path = path;
  c.raw = nlohmann::json::parse(*text, nullptr, false);
  if (c.raw.is_discarded() || !c.raw.is_object()) return Bad(path, "not a JSON object");
  const nlohmann::json& j = c.raw;
  try {
    if (!j.contains("part") || !j["part"].contains("mesh") ||
        !j["part"].contains("world_from_part"))
      return Bad(path, "needs part.mesh and part.world_from_part");
    c.part_mesh = Resolve(path, j["part"]["mesh"].get<std::string>());
    auto wfp =
        TransformFromJsonValue(j["part"]["world_from_part"], path + ": part.world_from_part");
    if (!wfp.ok()) return wfp.status();
    c.world_from_part = *wfp;
    if (j.contains("gauge") && j["gauge"].contains("mesh"))
      c.gauge_mesh = Resolve(path, j["gauge"]["mesh"].get<std::string>());
    if (!j.contains("viewpoints") || !j["viewpoints"].is_array() || j["viewpoints"].empty())
      return Bad(path, "needs a non-empty viewpoints array");
    for (std::size_t i = 0; i < j["viewpoints"].size(); ++i) {
      auto vp = ReadViewpoint(path, j, i);
      if (!vp.ok()) return vp.status();
      c.viewpoints.push_back(*std::move(vp));
    }
    if (j.contains("tolerance_mm")) c.error_map.tolerance_mm = j["tolerance_mm"].get<double>();
    if (j.contains("error_map")) {
      const auto& e = j["error_map"];
      c.error_map.max_distance_mm = e.value("max_distance_mm", c.error_map.max_distance_mm);
      c.error_map.allowed_fraction_outside =
          e.value("allowed_fraction_outside", c.error_map.allowed_fraction_outside);
      c.error_map.histogram_bins = e.value("histogram_bins", c.error_map.histogram_bins);
    }
    if (j.contains("filter")) {
      const auto& f = j["filter"];
      c.filter = f.value("enabled", true);
      c.filter_settings.link_distance_mm =
          f.value("link_distance_mm", c.filter_settings.link_distance_mm);
      c.filter_settings.min_cluster_points =
          f.value("min_cluster_points", c.filter_settings.min_cluster_points);
      c.filter_settings.connectivity = f.value("connectivity", c.filter_settings.connectivity);
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
  auto old = ReadFileToString(cell.path, 16 << 20);
  if (!old.ok()) return old.status();
  if (auto st = WriteStringAtomically(cell.path + ".bak", *old); !st.ok()) return st;
  return WriteStringAtomically(cell.path, j.dump(2) + "\n");
}

}  // namespace surfinspect::client
