// Closed-form absolute orientation (B. K. P. Horn, "Closed-form solution of
// absolute orientation using unit quaternions", JOSA A 4(4), 1987): the
// rigid transform that best maps one point set onto its partner set in the
// weighted least-squares sense. This is the ICP step of the paper, eq. (4).
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "absl/status/statusor.h"

namespace surfinspect {

// Returns to_from minimising sum_i w_i |to_from * from_i - to_i|^2. `weights`
// may be empty (all 1). Fails with fewer than 3 pairs, mismatched sizes,
// non-finite input, or a degenerate (collinear) configuration.
absl::StatusOr<Eigen::Isometry3d> HornAbsoluteOrientation(const std::vector<Eigen::Vector3d>& from,
                                                          const std::vector<Eigen::Vector3d>& to,
                                                          const std::vector<double>& weights = {});

}  // namespace surfinspect
