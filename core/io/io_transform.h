// Transform files: JSON `{"matrix": [[r00,r01,r02,tx],[..],[..],[0,0,0,1]]}`,
// row-major, translation in millimetres. Other keys are ignored on read.
#pragma once

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <string>

#include "absl/status/statusor.h"

namespace surfinspect {

absl::StatusOr<Eigen::Isometry3d> ReadTransformJson(const std::string& path);
absl::StatusOr<Eigen::Isometry3d> ParseTransformJson(const std::string& text,
                                                     const std::string& what);
// The same on an already parsed value (e.g. a field of cell.json).
absl::StatusOr<Eigen::Isometry3d> TransformFromJsonValue(const nlohmann::json& j,
                                                         const std::string& what);
nlohmann::json TransformToJsonValue(const Eigen::Isometry3d& t);  // {"matrix": [[...]]}
std::string TransformToJson(const Eigen::Isometry3d& t);          // pretty, full precision
absl::Status WriteTransformJson(const std::string& path, const Eigen::Isometry3d& t);

}  // namespace surfinspect
