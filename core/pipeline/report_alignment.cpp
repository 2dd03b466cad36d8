#include "core/pipeline/report_alignment.h"

#include "core/plan/plan_alignment.h"

namespace surfinspect {

std::optional<ReportAlignment> ReportAlignmentOf(const PlanOutcome& outcome) {
  const AlignmentOutcome& a = outcome.alignment;
  if (a.mode == AlignmentMode::kCalibrated) return std::nullopt;
  ReportAlignment out;
  out.mode = AlignmentModeName(a.mode);
  out.aligned = a.aligned;
  out.failure = a.failure;
  out.note = a.note;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out.matrix.push_back(a.correction.matrix()(r, c));
  out.translation_mm = a.x.head<3>();
  out.rotation_deg = a.x.tail<3>() * 180 / M_PI;
  out.correction_mm = a.correction_mm;
  out.correction_deg = a.correction_deg;
  out.max_correction_mm = a.max_correction_mm;
  out.max_correction_deg = a.max_correction_deg;
  out.within_max_correction = a.within_max_correction;
  out.rms_before_mm = a.rms_before_mm;
  out.rms_after_mm = a.rms_after_mm;
  out.dofs = a.dofs;
  out.iterations = a.iterations;
  out.converged = a.converged;
  for (int d = 0; d < kRigidDofs; ++d)
    if (a.mode == AlignmentMode::kBestFit && a.locked.IsLocked(d))
      out.locked.push_back(kDofKeys[d]);
  out.points_used = a.points_used;
  out.inliers = a.inliers;
  for (const AlignmentReferenceResult& r : a.references) {
    ReportAlignmentReference x{r.name,        r.kind,   r.measured, r.nominal_mm,
                               r.measured_mm, r.points, {}};
    for (std::size_t k = 0; k < r.directions.size(); ++k)
      x.locked.push_back({r.directions[k], k < r.before_mm.size() ? r.before_mm[k] : NAN,
                          k < r.after_mm.size() ? r.after_mm[k] : NAN});
    out.references.push_back(std::move(x));
  }
  return out;
}

absl::Status CheckReportAlignment(const std::optional<ReportAlignment>& alignment) {
  if (alignment && alignment->matrix.size() != 16)
    return absl::DataLossError("report.alignment.matrix: not 16 numbers");
  return absl::OkStatus();
}

}  // namespace surfinspect
