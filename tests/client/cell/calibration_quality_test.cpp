// Every field of the calibration-quality JSON against the CalibrationResult
// it came from, through the wire message both the CLI and the agent read.
#include "client/cell/calibration_quality.h"

#include <gtest/gtest.h>

#include "core/registration/calibration.h"
#include "proto/convert.h"

namespace surfinspect::client {
namespace {

TEST(CalibrationQualityJsonTest, EveryFieldFromTheResult) {
  CalibrationResult r;
  r.rms_mm = 0.0123;
  r.icp.iterations = 17;
  r.icp.converged = true;
  r.icp.stop_reason = IcpStopReason::kRelativeChange;
  r.icp.cost_history = {4.5, 0.25, 0.125};
  r.inlier_fraction = 0.875;
  r.sigma_translation_um = 3.25;
  r.sigma_rotation_deg = 0.0015;
  r.degenerate = true;
  r.degeneracy_ratio = 0.0005;
  r.residual_p50_mm = 0.01;
  r.residual_p95_mm = 0.02;
  r.residual_p99_mm = 0.03;
  r.filtered_points = 421;
  r.warnings = {"plane only", "few points"};
  v1::CalibrateResponse resp;
  wire::CalibrationToProto(r, &resp);
  const nlohmann::json j = CalibrationQualityJson(resp.quality());

  EXPECT_EQ(j.size(), 15u) << j.dump();
  EXPECT_EQ(j.at("rms_mm").get<double>(), r.rms_mm);
  EXPECT_EQ(j.at("iterations").get<int>(), r.icp.iterations);
  EXPECT_EQ(j.at("converged").get<bool>(), r.icp.converged);
  EXPECT_EQ(j.at("stop_reason").get<std::string>(), ToString(r.icp.stop_reason));
  EXPECT_EQ(j.at("inlier_fraction").get<double>(), r.inlier_fraction);
  EXPECT_EQ(j.at("sigma_translation_um").get<double>(), r.sigma_translation_um);
  EXPECT_EQ(j.at("sigma_rotation_deg").get<double>(), r.sigma_rotation_deg);
  EXPECT_EQ(j.at("degenerate").get<bool>(), r.degenerate);
  EXPECT_EQ(j.at("degeneracy_ratio").get<double>(), r.degeneracy_ratio);
  EXPECT_EQ(j.at("residual_p50_mm").get<double>(), r.residual_p50_mm);
  EXPECT_EQ(j.at("residual_p95_mm").get<double>(), r.residual_p95_mm);
  EXPECT_EQ(j.at("residual_p99_mm").get<double>(), r.residual_p99_mm);
  EXPECT_EQ(j.at("filtered_points").get<std::size_t>(), r.filtered_points);
  EXPECT_EQ(j.at("cost_history_mm2").get<std::vector<double>>(), r.icp.cost_history);
  EXPECT_EQ(j.at("warnings").get<std::vector<std::string>>(), r.warnings);
}

}  // namespace
}  // namespace surfinspect::client
