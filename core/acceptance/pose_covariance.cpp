#include "core/acceptance/pose_covariance.h"

namespace surfinspect {

Eigen::Matrix<double, 3, 6> WorldPointJacobian(const Eigen::Isometry3d& world_from_gauge,
                                               const Eigen::Vector3d& p_world) {
  const Eigen::Vector3d q = world_from_gauge.inverse() * p_world;
  Eigen::Matrix3d skew;
  skew << 0, -q.z(), q.y(), q.z(), 0, -q.x(), -q.y(), q.x(), 0;
  Eigen::Matrix<double, 3, 6> j;
  j << -skew, Eigen::Matrix3d::Identity();
  return world_from_gauge.linear() * j;
}

Eigen::Matrix3d WorldPointCovariance(const Eigen::Isometry3d& world_from_gauge,
                                     const PoseCovariance& covariance,
                                     const Eigen::Vector3d& p_world) {
  const Eigen::Matrix<double, 3, 6> j = WorldPointJacobian(world_from_gauge, p_world);
  return j * covariance * j.transpose();
}

}  // namespace surfinspect
