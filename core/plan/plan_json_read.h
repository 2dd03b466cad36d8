// Reading the plan's JSON form (docs/inspection-plan.md): typed fields whose
// errors name the field as a JSON path ("plan.holes[2].axis: zero vector"),
// InvalidArgument. Shared by the plan's parts that have a parser of their
// own (inspection_plan_json.cpp, plan_alignment.cpp).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "core/types/status_macros.h"

namespace surfinspect::plan_json {

absl::Status Bad(const std::string& path, absl::string_view what);
std::string Index(const std::string& path, std::size_t i);  // "path[i]"
// An object with no keys but `allowed`.
absl::Status CheckKeys(const nlohmann::json& j, const std::string& path,
                       std::initializer_list<const char*> allowed);
absl::StatusOr<double> Number(const nlohmann::json& j, const std::string& path);  // finite
absl::StatusOr<Eigen::Vector3d> Vector3(const nlohmann::json& j, const std::string& path);
absl::StatusOr<Eigen::Vector3d> UnitVector(const nlohmann::json& j, const std::string& path);
absl::StatusOr<std::string> String(const nlohmann::json& j, const std::string& path);
absl::StatusOr<bool> Bool(const nlohmann::json& j, const std::string& path);

// An optional number: `out` is set when `key` is present.
template <typename T>
absl::Status OptionalNumber(const nlohmann::json& j, const char* key, const std::string& path,
                            T& out) {
  if (!j.contains(key)) return absl::OkStatus();
  ASSIGN_OR_RETURN(auto v, Number(j[key], absl::StrCat(path, ".", key)));
  out = v;
  return absl::OkStatus();
}

// An array, each item read by parse(item, "path[i]").
template <typename T, typename F>
absl::Status List(const nlohmann::json& j, const std::string& path, F parse, std::vector<T>& out) {
  if (!j.is_array()) return Bad(path, "must be an array");
  for (std::size_t i = 0; i < j.size(); ++i) {
    ASSIGN_OR_RETURN(auto item, parse(j[i], Index(path, i)));
    out.push_back(std::move(item));
  }
  return absl::OkStatus();
}

}  // namespace surfinspect::plan_json
