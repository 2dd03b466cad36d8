// core/acceptance/sphere_spacing.cpp and core/acceptance/pose_covariance.cpp:
// the propagated calibration σ against a Monte Carlo of pose errors drawn
// from the covariance, for spheres from one view and from two.
#include "core/acceptance/sphere_spacing.h"

#include <gtest/gtest.h>

#include <random>

namespace surfinspect {
namespace {

Eigen::Isometry3d Exp(const Eigen::Matrix<double, 6, 1>& x) {
  Eigen::Isometry3d d = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d w = x.head<3>();
  if (w.norm() > 0) d.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
  d.translation() = x.tail<3>();
  return d;
}

PoseCovariance SomeCovariance() {
  Eigen::Matrix<double, 6, 6> a = Eigen::Matrix<double, 6, 6>::Random();
  a.topRows<3>() *= 2e-6;     // rad
  a.bottomRows<3>() *= 1e-3;  // mm
  return a * a.transpose();
}

TEST(PoseCovariance, JacobianMatchesAFiniteDifference) {
  Eigen::Isometry3d world_from_gauge = Eigen::Isometry3d::Identity();
  world_from_gauge.rotate(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()));
  world_from_gauge.translation() = Eigen::Vector3d(600, 100, 0);
  const Eigen::Vector3d p(650, 80, 60);
  const Eigen::Matrix<double, 3, 6> j = WorldPointJacobian(world_from_gauge, p);
  for (int k = 0; k < 6; ++k) {
    Eigen::Matrix<double, 6, 1> x = Eigen::Matrix<double, 6, 1>::Zero();
    x(k) = 1e-7;
    // p = world_from_gauge * exp(x) * gauge_from_sensor * s, with gauge_from_sensor * s = q.
    const Eigen::Vector3d q = world_from_gauge.inverse() * p;
    const Eigen::Vector3d moved = world_from_gauge * (Exp(x) * q);
    EXPECT_LT(((moved - p) / 1e-7 - j.col(k)).norm(), 1e-5) << k;
  }
}

TEST(SphereSpacing, CalibrationSigmaMatchesMonteCarlo) {
  ProbingError a, b;
  a.fit.centre = {500, 100, 50};
  b.fit.centre = {700, 100, 50};
  ViewCalibrationUncertainty va{Eigen::Isometry3d::Identity(), SomeCovariance()};
  ViewCalibrationUncertainty vb = va;
  va.world_from_gauge.translation() = Eigen::Vector3d(480, 100, 0);
  vb.world_from_gauge.translation() = Eigen::Vector3d(720, 100, 0);
  vb.covariance = SomeCovariance();
  for (bool same : {true, false}) {
    const ViewCalibrationUncertainty& vb_used = same ? va : vb;
    const SphereSpacing s = ComputeSphereSpacing(a, va, b, vb_used, same, 200, 0);
    EXPECT_NEAR(s.sd_mm, 0, 1e-12);
    std::mt19937_64 rng(7);
    std::normal_distribution<double> g;
    const Eigen::Matrix<double, 6, 6> la = va.covariance.llt().matrixL();
    const Eigen::Matrix<double, 6, 6> lb = vb_used.covariance.llt().matrixL();
    double sum2 = 0;
    const int n = 4000;
    for (int i = 0; i < n; ++i) {
      Eigen::Matrix<double, 6, 1> za, zb;
      for (int k = 0; k < 6; ++k) za(k) = g(rng), zb(k) = g(rng);
      const Eigen::Matrix<double, 6, 1> xa = la * za,
                                        xb = same ? xa : Eigen::Matrix<double, 6, 1>(lb * zb);
      const auto move = [](const ViewCalibrationUncertainty& v,
                           const Eigen::Matrix<double, 6, 1>& x, const Eigen::Vector3d& p) {
        return Eigen::Vector3d(v.world_from_gauge * (Exp(x) * (v.world_from_gauge.inverse() * p)));
      };
      const double len = (move(va, xa, a.fit.centre) - move(vb_used, xb, b.fit.centre)).norm();
      sum2 += (len - 200) * (len - 200) / n;
    }
    if (same) {  // one rigid pose error keeps the distance: nothing from the calibration
      EXPECT_LT(s.u_calibration_mm, 1e-12);
      EXPECT_LT(std::sqrt(sum2), 1e-6);
    } else {
      EXPECT_NEAR(std::sqrt(sum2) / s.u_calibration_mm, 1.0, 0.06);
    }
  }
}

TEST(SphereSpacing, FitAndArtefactUncertaintiesAdd) {
  ProbingError a, b;
  a.fit.centre = {0, 0, 0};
  b.fit.centre = {200.01, 0, 0};
  a.centre_covariance = Eigen::Vector3d(9e-6, 1, 1).asDiagonal();  // only x counts
  b.centre_covariance = Eigen::Vector3d(16e-6, 1, 1).asDiagonal();
  const SphereSpacing s = ComputeSphereSpacing(a, {}, b, {}, false, 200, 0.012);
  EXPECT_NEAR(s.sd_mm, 0.01, 1e-9);
  EXPECT_NEAR(s.u_fit_mm, 0.005, 1e-9);
  EXPECT_NEAR(s.u_sd_mm, 0.013, 1e-9);
}

}  // namespace
}  // namespace surfinspect
