// The acceptance test of a whole cell in the style of VDI/VDE 2634 Part 2
// (single view) and Part 3 (several views): every artefact measurement of
// artefacts.json is fitted in its viewpoint's world-frame scan (already
// filtered and registered with the cell's calibration by the caller) and
// reduced to the guideline's figures, each with its standard uncertainty
// u (k = 1), its expanded uncertainty U = 2u, its MPE and pass/fail:
//   PF, PS  the largest |value| over the sphere measurements (probing_error.h)
//   SD      per ball-bar position (sphere_spacing.h)
//   F       the largest over the plate measurements (flatness.h)
// Pass means |value| <= MPE, as the guideline states its acceptance; the
// uncertainty is reported beside it, not subtracted (no ISO 14253-1 rule).
// Where this deviates from the guideline is listed in `deviations`.
#pragma once

#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/acceptance/artefacts.h"
#include "core/acceptance/flatness.h"
#include "core/acceptance/probing_error.h"
#include "core/acceptance/sphere_spacing.h"

namespace surfinspect {

// The world-frame cloud of measurement `name` seen from `view`.
using WorldScanFn =
    std::function<absl::StatusOr<PointCloud>(const std::string& name, const std::string& view)>;

struct AcceptanceFigure {
  std::string measurement;  // which measurement gave the value
  double value_mm = 0, u_mm = 0, mpe_mm = 0;
  bool pass = false;
};

struct SpacingResult {
  BallBarPosition position;  // a copy: the result outlives the Artefacts given
  SphereSpacing spacing;
  ProbingError a, b;
  bool pass = false;
};

struct AcceptanceResult {
  std::vector<std::pair<std::string, ProbingError>> spheres;
  std::vector<std::pair<std::string, Flatness>> plates;
  std::vector<SpacingResult> sd;
  AcceptanceFigure pf, ps, f;
  bool pass = false;  // every figure passes
};

// Every viewpoint a measurement names needs its calibration uncertainty in
// `views` (InvalidArgument otherwise). Errors of a fit name the measurement.
absl::StatusOr<AcceptanceResult> RunAcceptance(
    const Artefacts& artefacts, const std::map<std::string, ViewCalibrationUncertainty>& views,
    const WorldScanFn& scan);

// The report, schema "surfinspect.acceptance/1": PF_mm, PS_mm, F_mm (each
// {value, u, U, mpe, pass, measurement}), SD_mm [per position], verdict,
// the per-measurement details, the cross-view summary and the deviations.
nlohmann::json AcceptanceReportJson(const AcceptanceResult& result, const Artefacts& artefacts);

}  // namespace surfinspect
