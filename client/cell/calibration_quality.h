// The one JSON form of a viewpoint calibration's quality, written by
// `surfinspect calibrate --report` and stored per viewpoint in cell.json by
// `cell-agent calibrate`. Names carry their unit (mm, um, deg, mm2);
// counts and fractions are unit-free. Built from the wire message, so a
// local and a remote calibration write the same bytes.
#pragma once

#include <nlohmann/json.hpp>

#include "surfinspect/v1/inspection.pb.h"

namespace surfinspect::client {

// Keys: rms_mm, iterations, converged, stop_reason, inlier_fraction,
// sigma_translation_um, sigma_rotation_deg, degenerate, degeneracy_ratio,
// residual_p50_mm, residual_p95_mm, residual_p99_mm, filtered_points,
// cost_history_mm2 (per iteration), warnings.
nlohmann::json CalibrationQualityJson(const ::surfinspect::v1::CalibrationQuality& quality);

}  // namespace surfinspect::client
