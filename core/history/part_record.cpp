#include "core/history/part_record.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"

namespace surfinspect {
namespace {

double Number(const nlohmann::json& j, const char* key) {
  const auto it = j.find(key);
  return it != j.end() && it->is_number() ? it->get<double>() : NAN;
}

}  // namespace

absl::Status FillFromReportJson(const std::string& text, const std::string& where,
                                PartRecord* record) {
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object())
    return absl::DataLossError(absl::StrCat(where, ": not a JSON object"));
  if (!j.contains("verdict") || !j["verdict"].is_string())
    return absl::DataLossError(absl::StrCat(where, ": no verdict"));
  record->verdict = j["verdict"].get<std::string>();
  record->characteristics.clear();
  const nlohmann::json& list =
      j.contains("characteristics") ? j["characteristics"] : nlohmann::json::array();
  if (!list.is_array()) return absl::DataLossError(absl::StrCat(where, ": characteristics"));
  for (const nlohmann::json& c : list) {
    if (!c.is_object() || !c.contains("name") || !c["name"].is_string())
      return absl::DataLossError(absl::StrCat(where, ": a characteristic without a name"));
    CharacteristicRecord r;
    r.name = c["name"].get<std::string>();
    r.type = c.value("type", std::string());
    r.verdict = c.value("verdict", std::string());
    r.mean_mm = Number(c, "mean_mm");
    r.min_mm = Number(c, "min_mm");
    r.max_mm = Number(c, "max_mm");
    r.stddev_mm = Number(c, "stddev_mm");
    r.value_mm = r.type == "point" ? Number(c, "value_mm") : r.mean_mm;
    if (c.contains("tolerance_mm") && c["tolerance_mm"].is_object()) {
      r.lower_mm = Number(c["tolerance_mm"], "lower");
      r.upper_mm = Number(c["tolerance_mm"], "upper");
    }
    r.points =
        c.contains("points") && c["points"].is_number_integer() ? c["points"].get<int64_t>() : 0;
    record->characteristics.push_back(std::move(r));
  }
  record->defects_json = j.contains("defects") ? j["defects"].dump() : "[]";
  return absl::OkStatus();
}

}  // namespace surfinspect
