#include "core/plan/alignment.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/plan/holes.h"
#include "core/plan/plan_alignment.h"
#include "core/registration/locked_best_fit.h"
#include "core/registration/rps_fit.h"
#include "core/types/cancel.h"
#include "core/types/percentile.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

// A surface reference needs this many points within its radius: the
// median of fewer is at the mercy of a few noisy ones.
constexpr std::size_t kMinSurfacePoints = 20;
// The best-fit uses at most this many points (a stride over the matched
// ones): six unknowns, and each iteration queries every point.
constexpr std::size_t kMaxFitPoints = 60000;

double AngleDeg(const Eigen::Isometry3d& t) {
  return Eigen::AngleAxisd(t.linear()).angle() * 180 / M_PI;
}

// The surface references' measured places: per reference, the median
// deviation of the points whose closest CAD point lies within its radius,
// along its CAD normal. One pass over the map for all of them.
void MeasureSurfaceReferences(const ErrorMapResult& em, const InspectionPlan& plan,
                              std::vector<RpsReference>& refs,
                              std::vector<AlignmentReferenceResult>& out) {
  std::vector<std::vector<double>> deviations(refs.size());
  for (std::size_t i = 0; i < em.triangle_id.size(); ++i) {
    if (em.triangle_id[i] == UINT32_MAX) continue;
    const Eigen::Vector3d c = em.closest_point[i].cast<double>();
    for (std::size_t k = 0; k < refs.size(); ++k) {
      const double r = plan.alignment.references[k].radius_mm;
      if (out[k].kind == "surface" && (c - refs[k].nominal_mm).squaredNorm() <= r * r)
        deviations[k].push_back(em.deviation_mm[i]);
    }
  }
  for (std::size_t k = 0; k < refs.size(); ++k) {
    if (out[k].kind != "surface") continue;
    out[k].points = deviations[k].size();
    if (deviations[k].size() < kMinSurfacePoints) continue;
    const double d = MedianInPlace(deviations[k]);
    refs[k].measured_mm = refs[k].nominal_mm + d * refs[k].directions[0];
    out[k].measured = true;
  }
}

// The hole references' centres, measured on the views.
absl::Status MeasureHoleReferences(const AlignmentInputs& in, const InspectionPlan& plan,
                                   const std::atomic<bool>* cancel, std::vector<RpsReference>& refs,
                                   std::vector<AlignmentReferenceResult>& out) {
  std::vector<PlanHole> holes;
  std::vector<std::size_t> which;
  for (std::size_t k = 0; k < refs.size(); ++k)
    for (const PlanHole& h : plan.holes)
      if (h.name == plan.alignment.references[k].hole) holes.push_back(h), which.push_back(k);
  if (holes.empty()) return absl::OkStatus();
  ASSIGN_OR_RETURN(auto measured, MeasureHoles(holes, in.views, {}, cancel));
  for (std::size_t j = 0; j < holes.size(); ++j) {
    AlignmentReferenceResult& r = out[which[j]];
    r.points = measured[j].edge_points;
    r.measured = measured[j].measured;
    if (r.measured) refs[which[j]].measured_mm = measured[j].measured_position_mm;
  }
  return absl::OkStatus();
}

absl::StatusOr<AlignmentOutcome> MeasureRps(const AlignmentInputs& in, const InspectionPlan& plan,
                                            const std::atomic<bool>* cancel) {
  AlignmentOutcome o;
  std::vector<RpsReference> refs = NominalRpsReferences(plan, in.part.mesh());
  for (std::size_t k = 0; k < refs.size(); ++k) {
    AlignmentReferenceResult r;
    r.name = refs[k].name;
    const std::string& hole = plan.alignment.references[k].hole;
    r.kind = hole.empty() ? "surface" : refs[k].directions.size() == 1 ? "slot" : "hole";
    r.nominal_mm = refs[k].nominal_mm;
    r.directions = refs[k].directions;
    o.references.push_back(std::move(r));
  }
  MeasureSurfaceReferences(in.error_map, plan, refs, o.references);
  RETURN_IF_ERROR(MeasureHoleReferences(in, plan, cancel, refs, o.references));
  for (const AlignmentReferenceResult& r : o.references)
    if (!r.measured) {
      o.failure =
          r.kind == "surface"
              ? absl::StrCat("reference ", r.name, ": ", r.points,
                             " points within its radius, at least ", kMinSurfacePoints, " needed")
              : absl::StrCat("reference ", r.name, ": its ", r.kind, " was not measured");
      return o;
    }
  auto solved = SolveRps(refs);
  if (!solved.ok()) {
    o.failure = std::string(solved.status().message());
    return o;
  }
  o.aligned = true;
  o.correction = solved->nominal_from_measured;
  o.x = solved->x;
  o.rms_before_mm = solved->rms_before_mm;
  o.rms_after_mm = solved->rms_after_mm;
  o.dofs = kRigidDofs;
  o.converged = solved->converged;
  o.iterations = solved->iterations;
  for (std::size_t k = 0; k < refs.size(); ++k) {
    o.references[k].measured_mm = refs[k].measured_mm;
    o.references[k].before_mm = solved->residuals[k].before_mm;
    o.references[k].after_mm = solved->residuals[k].after_mm;
    o.correction_mm = std::max(o.correction_mm,
                               (o.correction * refs[k].measured_mm - refs[k].measured_mm).norm());
  }
  return o;
}

// The matched points of the plan's best-fit regions (all when none), in
// the calibrated part frame, a stride of them when there are many; and the
// regions' triangle mask for the fit's pairs.
absl::StatusOr<PointCloud> FitPoints(const AlignmentInputs& in, const InspectionPlan& plan,
                                     std::vector<uint8_t>* mask) {
  const std::vector<std::string>& names = plan.alignment.regions;
  if (!names.empty()) {
    ASSIGN_OR_RETURN(auto rp, ResolveInspectionPlan(plan, in.part.mesh()));
    mask->assign(rp.num_triangles, 0);
    for (std::size_t t = 0; t < rp.num_triangles; ++t)
      for (uint32_t k = rp.region_offsets[t]; k < rp.region_offsets[t + 1]; ++k)
        (*mask)[t] |= std::find(names.begin(), names.end(),
                                rp.plan.regions[rp.region_ids[k]].name) != names.end();
  }
  std::vector<std::size_t> use;
  const std::vector<uint32_t>& id = in.error_map.triangle_id;
  for (std::size_t i = 0; i < id.size(); ++i)
    if (id[i] != UINT32_MAX && (mask->empty() || (*mask)[id[i]])) use.push_back(i);
  const std::size_t stride =
      std::max<std::size_t>(1, (use.size() + kMaxFitPoints - 1) / kMaxFitPoints);
  const Eigen::Isometry3d part_from_world = in.world_from_part.inverse();
  std::vector<Eigen::Vector3f> points;
  for (std::size_t k = 0; k < use.size(); k += stride)
    points.push_back(
        (part_from_world * in.cloud_in_world.points[use[k]].cast<double>()).cast<float>());
  return PointCloud::Unorganized(std::move(points));
}

absl::StatusOr<AlignmentOutcome> MeasureBestFit(const AlignmentInputs& in,
                                                const InspectionPlan& plan,
                                                const std::atomic<bool>* cancel) {
  AlignmentOutcome o;
  const PlanAlignment& a = plan.alignment;
  o.locked = a.locked;
  o.dofs = a.locked.FreeCount();
  if (a.regions.empty())
    o.note =
        "a best-fit over the whole part minimises the very deviations it then judges: a shape "
        "error shrinks and spreads (docs/alignment.md)";
  std::vector<uint8_t> mask;
  ASSIGN_OR_RETURN(auto points, FitPoints(in, plan, &mask));
  LockedBestFitSettings s;
  s.max_correction_mm = a.max_correction_mm;
  s.max_correction_deg = a.max_correction_deg;
  s.threads = in.threads;
  auto fit = RunLockedBestFit(in.part, points, mask, a.locked, s, cancel);
  if (!fit.ok()) {
    if (fit.status().code() == absl::StatusCode::kCancelled) return fit.status();
    o.failure = std::string(fit.status().message());
    return o;
  }
  o.aligned = true;
  o.correction = fit->nominal_from_measured;
  o.x = fit->x;
  o.rms_before_mm = fit->rms_before_mm;
  o.rms_after_mm = fit->rms_after_mm;
  o.points_used = fit->points_used;
  o.inliers = fit->inliers;
  o.iterations = fit->iterations;
  o.converged = fit->converged;
  o.correction_mm = fit->correction_mm;
  if (!fit->converged)
    o.failure = absl::StrCat("the best-fit did not converge in ", fit->iterations, " steps");
  return o;
}

}  // namespace

absl::StatusOr<AlignmentOutcome> MeasureAlignment(const AlignmentInputs& in,
                                                  const InspectionPlan& plan,
                                                  const std::atomic<bool>* cancel) {
  AlignmentOutcome o;
  if (plan.alignment.mode == AlignmentMode::kRps) {
    ASSIGN_OR_RETURN(o, MeasureRps(in, plan, cancel));
  } else if (plan.alignment.mode == AlignmentMode::kBestFit) {
    ASSIGN_OR_RETURN(o, MeasureBestFit(in, plan, cancel));
  }
  o.mode = plan.alignment.mode;
  o.max_correction_mm = plan.alignment.max_correction_mm;
  o.max_correction_deg = plan.alignment.max_correction_deg;
  if (o.aligned) {
    o.correction_deg = AngleDeg(o.correction);
    o.within_max_correction =
        o.correction_mm <= o.max_correction_mm && o.correction_deg <= o.max_correction_deg;
  }
  return o;
}

void ApplyAlignmentVerdict(const AlignmentOutcome& a, CharacteristicsResult* result) {
  if (a.ok()) return;
  result->pass = false;
  const std::string why =
      !a.failure.empty()
          ? absl::StrCat("alignment (", AlignmentModeName(a.mode), ") failed: ", a.failure)
          : absl::StrFormat(
                "alignment (%s) corrects %.3f mm / %.3f deg, more than the %.3g mm / "
                "%.3g deg allowed",
                AlignmentModeName(a.mode), a.correction_mm, a.correction_deg, a.max_correction_mm,
                a.max_correction_deg);
  result->reason = result->reason.empty() ? why : absl::StrCat(why, "; ", result->reason);
}

}  // namespace surfinspect
