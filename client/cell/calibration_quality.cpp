#include "client/cell/calibration_quality.h"

#include <string>
#include <vector>

namespace surfinspect::client {

nlohmann::json CalibrationQualityJson(const ::surfinspect::v1::CalibrationQuality& q) {
  return {
      {"rms_mm", q.rms_mm()},
      {"iterations", q.iterations()},
      {"converged", q.converged()},
      {"stop_reason", q.stop_reason()},
      {"inlier_fraction", q.inlier_fraction()},
      {"sigma_translation_um", q.sigma_translation_um()},
      {"sigma_rotation_deg", q.sigma_rotation_deg()},
      {"degenerate", q.degenerate()},
      {"degeneracy_ratio", q.degeneracy_ratio()},
      {"residual_p50_mm", q.residual_p50_mm()},
      {"residual_p95_mm", q.residual_p95_mm()},
      {"residual_p99_mm", q.residual_p99_mm()},
      {"filtered_points", q.filtered_points()},
      {"cost_history_mm2", std::vector<double>(q.cost_history().begin(), q.cost_history().end())},
      {"warnings", std::vector<std::string>(q.warnings().begin(), q.warnings().end())}};
}

}  // namespace surfinspect::client
