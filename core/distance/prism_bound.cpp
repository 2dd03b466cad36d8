#include "core/distance/prism_bound.h"

#include <Eigen/Geometry>

namespace surfinspect {

PrismBound MakePrismBound(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                          const Eigen::Vector3d& c, const Eigen::Vector3d& n) {
  PrismBound bound;
  if (n.isZero()) return bound;
  const std::array<Eigen::Vector3d, 3> v{a, b, c};
  double longest2 = 0;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d e = v[(k + 1) % 3] - v[k];
    bound.edge[k] = e.cross(n).normalized();
    longest2 = std::max(longest2, e.squaredNorm());
  }
  bound.slack = 1e-12 + 2e-15 * longest2 / (b - a).cross(c - a).norm();
  return bound;
}

}  // namespace surfinspect
