#include "core/io/io_transform.h"

#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"
#include "core/io/atomic_file.h"
#include "core/types/status_macros.h"
#include "core/types/transform.h"

namespace surfinspect {

absl::StatusOr<Eigen::Isometry3d> ParseTransformJson(const std::string& text,
                                                     const std::string& what) {
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return absl::InvalidArgumentError(absl::StrCat(what, ": not valid JSON"));
  return TransformFromJsonValue(j, what);
}

absl::StatusOr<Eigen::Isometry3d> TransformFromJsonValue(const nlohmann::json& j,
                                                         const std::string& what) {
  const nlohmann::json* m = j.is_object() && j.contains("matrix") ? &j["matrix"] : nullptr;
  if (!m || !m->is_array() || m->size() != 4)
    return absl::InvalidArgumentError(
        absl::StrCat(what, ": expected {\"matrix\": [4 rows of 4 numbers]}"));
  RowMajor16 v{};
  for (int r = 0; r < 4; ++r) {
    const auto& row = (*m)[r];
    if (!row.is_array() || row.size() != 4)
      return absl::InvalidArgumentError(absl::StrCat(what, ": row ", r, " must hold 4 numbers"));
    for (int c = 0; c < 4; ++c) {
      if (!row[c].is_number())
        return absl::InvalidArgumentError(
            absl::StrCat(what, ": element (", r, ",", c, ") is not a number"));
      v[r * 4 + c] = row[c].get<double>();
    }
  }
  return FromRowMajor(v, what);
}

absl::StatusOr<Eigen::Isometry3d> ReadTransformJson(const std::string& path) {
  ASSIGN_OR_RETURN(auto text, ReadFileToString(path, 1 << 20));
  return ParseTransformJson(text, path);
}

nlohmann::json TransformToJsonValue(const Eigen::Isometry3d& t) {
  const RowMajor16 v = ToRowMajor(t);
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({v[r * 4], v[r * 4 + 1], v[r * 4 + 2], v[r * 4 + 3]});
  return {{"matrix", rows}};
}

std::string TransformToJson(const Eigen::Isometry3d& t) {
  return TransformToJsonValue(t).dump(2) + "\n";
}

absl::Status WriteTransformJson(const std::string& path, const Eigen::Isometry3d& t) {
  return WriteStringAtomically(path, TransformToJson(t));
}

}  // namespace surfinspect
