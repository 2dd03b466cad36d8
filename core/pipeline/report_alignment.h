// How the scan was aligned to the CAD, as report.json carries it
// ("alignment"; only when the plan asked for more than the calibrated
// frame, so the reports of other plans keep their bytes): the mode, the
// correction (its matrix, translation and rotation, and its size against
// the allowed maximum), the fit's RMS and degrees of freedom, each RPS
// reference's deviations along the directions it locked, before and after,
// and why an alignment failed (core/plan/alignment.h).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "core/plan/plan_evaluation.h"

namespace surfinspect {

struct ReportLockedDirection {
  Eigen::Vector3d direction = Eigen::Vector3d::Constant(NAN);  // unit, part frame
  double before_mm = NAN, after_mm = NAN;
};

struct ReportAlignmentReference {
  std::string name, kind;  // kind: "hole" | "slot" | "surface"
  bool measured = false;
  Eigen::Vector3d nominal_mm = Eigen::Vector3d::Constant(NAN);
  Eigen::Vector3d measured_mm = Eigen::Vector3d::Constant(NAN);  // as calibrated
  std::size_t points = 0;
  std::vector<ReportLockedDirection> locked;
};

struct ReportAlignment {
  std::string mode, failure, note;
  bool aligned = false, within_max_correction = true, converged = false;
  std::vector<double> matrix;  // the correction, 4 x 4 row-major, part frame
  Eigen::Vector3d translation_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d rotation_deg = Eigen::Vector3d::Zero();  // about x, y, z (rigid_dofs.h)
  double correction_mm = 0, correction_deg = 0, max_correction_mm = 0, max_correction_deg = 0;
  double rms_before_mm = NAN, rms_after_mm = NAN;
  int dofs = 0, iterations = 0;
  std::vector<std::string> locked;  // best_fit: "tx" .. "rz"
  std::size_t points_used = 0, inliers = 0;
  std::vector<ReportAlignmentReference> references;
};

// Set when the plan's alignment is not the calibrated frame.
std::optional<ReportAlignment> ReportAlignmentOf(const PlanOutcome& outcome);

// DataLoss naming the field for a matrix that is not 16 numbers.
absl::Status CheckReportAlignment(const std::optional<ReportAlignment>& alignment);

template <typename V, typename R>
void VisitReportAlignment(V& v, R& alignment) {
  v.Object("alignment", alignment, [](auto& w, auto& a) {
    w("mode", a.mode);
    w("aligned", a.aligned);
    w("failure", a.failure);
    w("note", a.note);
    w("matrix", a.matrix);
    w("translation_mm", a.translation_mm);
    w("rotation_deg", a.rotation_deg);
    w("correction_mm", a.correction_mm);
    w("correction_deg", a.correction_deg);
    w("max_correction_mm", a.max_correction_mm);
    w("max_correction_deg", a.max_correction_deg);
    w("within_max_correction", a.within_max_correction);
    w("rms_before_mm", a.rms_before_mm);
    w("rms_after_mm", a.rms_after_mm);
    w("dofs", a.dofs);
    w("locked", a.locked);
    w("points_used", a.points_used);
    w("inliers", a.inliers);
    w("iterations", a.iterations);
    w("converged", a.converged);
    w.List("references", a.references, [](auto& x, auto& r) {
      x("name", r.name);
      x("kind", r.kind);
      x("measured", r.measured);
      x("nominal_mm", r.nominal_mm);
      x("measured_mm", r.measured_mm);
      x("points", r.points);
      x.List("locked", r.locked, [](auto& y, auto& d) {
        y("direction", d.direction);
        y("before_mm", d.before_mm);
        y("after_mm", d.after_mm);
      });
    });
  });
}

}  // namespace surfinspect
