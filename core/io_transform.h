// Transform files: JSON `{"matrix": [[r00,r01,r02,tx],[..],[..],[0,0,0,1]]}`,
// row-major, translation in millimetres. Other keys are ignored on read.
#pragma once

#include <Eigen/Geometry>
#include <string>

#include "absl/status/statusor.h"

namespace surfinspect {

absl::StatusOr<Eigen::Isometry3d> ReadTransformJson(const std::string& path);
absl::StatusOr<Eigen::Isometry3d> ParseTransformJson(const std::string& text,
                                                     const std::string& what);
std::string TransformToJson(const Eigen::Isometry3d& t);  // pretty, full precision
absl::Status WriteTransformJson(const std::string& path, const Eigen::Isometry3d& t);

}  // namespace surfinspect
