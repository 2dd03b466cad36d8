#include "core/plan/plan_json_read.h"

#include <cmath>

namespace surfinspect::plan_json {

using nlohmann::json;

absl::Status Bad(const std::string& path, absl::string_view what) {
  return absl::InvalidArgumentError(absl::StrCat(path, ": ", what));
}

std::string Index(const std::string& path, std::size_t i) {
  return absl::StrCat(path, "[", i, "]");
}

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
    ASSIGN_OR_RETURN(auto x, Number(j[a], Index(path, a)));
    v[a] = x;
  }
  return v;
}

absl::StatusOr<Eigen::Vector3d> UnitVector(const json& j, const std::string& path) {
  ASSIGN_OR_RETURN(auto v, Vector3(j, path));
  if (!(v.norm() > 1e-12)) return Bad(path, "zero vector");
  return Eigen::Vector3d(v.normalized());
}

absl::StatusOr<std::string> String(const json& j, const std::string& path) {
  if (!j.is_string()) return Bad(path, "must be a string");
  return j.get<std::string>();
}

absl::StatusOr<bool> Bool(const json& j, const std::string& path) {
  if (!j.is_boolean()) return Bad(path, "must be true or false");
  return j.get<bool>();
}

}  // namespace surfinspect::plan_json
