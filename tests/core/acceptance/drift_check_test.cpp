// core/acceptance/drift_check.cpp: planted moves of a viewpoint's pose are
// measured exactly and classified by limits and significance.
#include "core/acceptance/drift_check.h"

#include <gtest/gtest.h>

namespace surfinspect {
namespace {

DriftInput Input(const Eigen::Vector3d& move_mm, double rot_deg, double sigma_mm) {
  DriftInput in;
  in.world_from_gauge.translation() = Eigen::Vector3d(600, 100, 0);
  in.calibrated_world_from_sensor.translation() = Eigen::Vector3d(600, 100, 420);
  in.verified_world_from_sensor = in.calibrated_world_from_sensor;
  in.verified_world_from_sensor.pretranslate(move_mm);
  in.verified_world_from_sensor.rotate(
      Eigen::AngleAxisd(rot_deg * M_PI / 180, Eigen::Vector3d::UnitX()));
  in.calibration_covariance.bottomRightCorner<3, 3>() =
      Eigen::Matrix3d::Identity() * sigma_mm * sigma_mm / 2;
  in.verify_covariance = in.calibration_covariance;
  in.part_point_world = Eigen::Vector3d(600, 100, 20);
  return in;
}

TEST(DriftCheck, TranslationIsMeasuredAtSensorAndPart) {
  const DriftCheck d = CheckDrift(Input({0.020, 0, 0}, 0, 0.001), DriftLimits{});
  EXPECT_NEAR(d.at_sensor_um, 20, 1e-6);
  EXPECT_NEAR(d.at_part_um, 20, 1e-6);
  EXPECT_NEAR(d.rotation_deg, 0, 1e-9);
  EXPECT_NEAR(d.sigma_at_part_um, 1.0, 1e-6);
  EXPECT_TRUE(d.significant);
  EXPECT_EQ(d.verdict, DriftClass::kFail);
  EXPECT_NE(d.reason.find("recalibrate"), std::string::npos);
}

TEST(DriftCheck, RotationMovesThePartByItsLever) {
  // 0.001 deg about x at the sensor, 400 mm above the part: 6.98 µm there.
  const DriftCheck d = CheckDrift(Input({0, 0, 0}, 0.001, 0.001), DriftLimits{});
  EXPECT_NEAR(d.at_part_um, 400 * 0.001 * M_PI / 180 * 1000, 1e-3);
  EXPECT_NEAR(d.at_sensor_um, 0, 1e-6);
  EXPECT_NEAR(d.rotation_deg, 0.001, 1e-9);
  EXPECT_EQ(d.verdict, DriftClass::kWarn);  // beyond 5 µm, within 10 µm
}

TEST(DriftCheck, SmallOrInsignificantMovesDoNotFail) {
  EXPECT_EQ(CheckDrift(Input({0.002, 0, 0}, 0, 0.001), DriftLimits{}).verdict, DriftClass::kOk);
  // 20 µm against a combined σ of 10 µm: beyond the limit but not significant.
  const DriftCheck d = CheckDrift(Input({0.020, 0, 0}, 0, 0.010), DriftLimits{});
  EXPECT_FALSE(d.significant);
  EXPECT_EQ(d.verdict, DriftClass::kWarn);
  EXPECT_NE(d.reason.find("not significant"), std::string::npos);
}

TEST(DriftCheck, LimitsAreValidated) {
  EXPECT_TRUE(ValidateDriftLimits(DriftLimits{}).ok());
  DriftLimits l;
  l.warn_um = 20;
  EXPECT_FALSE(ValidateDriftLimits(l).ok());
  l = {};
  l.significance = 0;
  EXPECT_FALSE(ValidateDriftLimits(l).ok());
}

}  // namespace
}  // namespace surfinspect
