#include "core/plan/alignment.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/plan/holes.h"
#include "core/plan/plan_alignment.h"
#include "core/registration/locked_best_fit.h"
#include "core/registration/rps_fit.h"
#include "core/types/percentile.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

// A surface reference needs this many points within its radius: the
// median of fewer is at the mercy of a few noisy ones.
constexpr std::size_t kMinSurfacePoints = 20;
// The best-fit uses at most this many points (a stride over the scan):
// six unknowns, and each iteration queries every point.
constexpr std::size_t kMaxFitPoints = 20000;

double AngleDeg(const Eigen::Isometry3d& t) {
  return Eigen::AngleAxisd(t.linear()).angle() * 180 / M_PI;
}

// What an RPS solve and a best-fit both give.
template <typename Solution>
void TakeSolution(const Solution& s, AlignmentOutcome& o) {
  o.aligned = true;
  o.correction = s.nominal_from_measured;
  o.x = s.x;
  o.rms_before_mm = s.rms_before_mm;
  o.rms_after_mm = s.rms_after_mm;
  o.iterations = s.iterations;
  o.converged = s.converged;
}

// The indices of the valid points of `cloud` for which keep(point) holds,
// ascending: parallel over blocks, concatenated in block order.
template <typename Keep>
std::vector<std::size_t> SelectPoints(const PointCloud& cloud, Keep keep) {
  constexpr std::size_t kBlock = std::size_t{1} << 16;
  const std::size_t n = cloud.size(), blocks = (n + kBlock - 1) / kBlock;
  std::vector<std::vector<std::size_t>> picked(blocks);
  tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
    for (std::size_t i = b * kBlock; i < std::min(n, (b + 1) * kBlock); ++i)
      if (PointCloud::IsValid(cloud.points[i]) && keep(cloud.points[i])) picked[b].push_back(i);
  });
  std::vector<std::size_t> out;
  for (const auto& p : picked) out.insert(out.end(), p.begin(), p.end());
  return out;
}

// The surface references' measured places: per reference, the median
// signed distance of the points whose closest CAD point lies within its
// radius, along its CAD normal. Only the points within radius + the match
// distance of a reference (a cheap test in the world frame) can qualify;
// they alone are queried.
void MeasureSurfaceReferences(const AlignmentInputs& in, const InspectionPlan& plan,
                              std::vector<RpsReference>& refs,
                              std::vector<AlignmentReferenceResult>& out) {
  const Eigen::Isometry3d part_from_world = in.world_from_part.inverse();
  std::vector<std::size_t> surface;
  std::vector<Eigen::Vector3f> centre;  // per surface reference, world frame
  std::vector<float> reach2;
  for (std::size_t k = 0; k < refs.size(); ++k) {
    if (out[k].kind != "surface") continue;
    const double reach = plan.alignment.references[k].radius_mm + std::min(in.max_distance_mm, 1e6);
    surface.push_back(k);
    centre.push_back((in.world_from_part * refs[k].nominal_mm).cast<float>());
    reach2.push_back(static_cast<float>(reach * reach));
  }
  const auto near = [&](const Eigen::Vector3f& p, std::size_t j) {
    return (p - centre[j]).squaredNorm() <= reach2[j];
  };
  const std::vector<std::size_t> candidates = SelectPoints(in.cloud_in_world, [&](const auto& p) {
    for (std::size_t j = 0; j < surface.size(); ++j)
      if (near(p, j)) return true;
    return false;
  });
  std::vector<std::vector<double>> deviations(surface.size());
  for (std::size_t i : candidates) {
    const Eigen::Vector3f& p = in.cloud_in_world.points[i];
    const ClosestPoint c = in.part.Closest(part_from_world * p.cast<double>(), in.max_distance_mm);
    for (std::size_t j = 0; j < surface.size() && c.matched(); ++j) {
      const double r = plan.alignment.references[surface[j]].radius_mm;
      if (near(p, j) && (c.point - refs[surface[j]].nominal_mm).squaredNorm() <= r * r)
        deviations[j].push_back(c.signed_distance_mm);
    }
  }
  for (std::size_t j = 0; j < surface.size(); ++j) {
    const std::size_t k = surface[j];
    out[k].points = deviations[j].size();
    if (deviations[j].size() < kMinSurfacePoints) {
      out[k].reason = absl::StrCat(out[k].points, " points within its radius, at least ",
                                   kMinSurfacePoints, " needed");
      continue;
    }
    refs[k].measured_mm = refs[k].nominal_mm + MedianInPlace(deviations[j]) * refs[k].directions[0];
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
    r.reason = measured[j].reason;
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
  MeasureSurfaceReferences(in, plan, refs, o.references);
  RETURN_IF_ERROR(MeasureHoleReferences(in, plan, cancel, refs, o.references));
  for (const AlignmentReferenceResult& r : o.references)
    if (!r.measured) {
      o.failure = r.kind == "surface" ? absl::StrCat("reference ", r.name, ": ", r.reason)
                                      : absl::StrCat("reference ", r.name, ": its ", r.kind,
                                                     " was not measured (", r.reason, ")");
      return o;
    }
  auto solved = SolveRps(refs);
  if (!solved.ok()) {
    o.failure = std::string(solved.status().message());
    return o;
  }
  TakeSolution(*solved, o);
  o.dofs = kRigidDofs;
  for (std::size_t k = 0; k < refs.size(); ++k) {
    o.references[k].measured_mm = refs[k].measured_mm;
    o.references[k].before_mm = solved->residuals[k].before_mm;
    o.references[k].after_mm = solved->residuals[k].after_mm;
    o.correction_mm = std::max(o.correction_mm,
                               (o.correction * refs[k].measured_mm - refs[k].measured_mm).norm());
  }
  return o;
}

// The points the best-fit uses, in the calibrated part frame: a stride
// over the scan's valid points, and with regions, of a four times denser
// stride those whose closest CAD triangle lies in them (the mask the fit
// pairs with, also returned).
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
  const Eigen::Isometry3d part_from_world = in.world_from_part.inverse();
  const std::vector<std::size_t> valid =
      SelectPoints(in.cloud_in_world, [](const auto&) { return true; });
  const std::size_t want = mask->empty() ? kMaxFitPoints : 4 * kMaxFitPoints;
  const std::size_t step = std::max<std::size_t>(1, (valid.size() + want - 1) / want);
  std::vector<Eigen::Vector3f> points;
  for (std::size_t k = 0; k < valid.size(); k += step)
    points.push_back(
        (part_from_world * in.cloud_in_world.points[valid[k]].cast<double>()).cast<float>());
  if (mask->empty()) return PointCloud::Unorganized(std::move(points));
  std::vector<uint8_t> in_region(points.size(), 0);
  tbb::parallel_for(std::size_t{0}, points.size(), [&](std::size_t k) {
    const ClosestPoint c = in.part.Closest(points[k].cast<double>(), in.max_distance_mm);
    in_region[k] = c.matched() && (*mask)[c.triangle_id];
  });
  std::vector<Eigen::Vector3f> kept;
  for (std::size_t k = 0; k < points.size(); ++k)
    if (in_region[k]) kept.push_back(points[k]);
  const std::size_t cap =
      std::max<std::size_t>(1, (kept.size() + kMaxFitPoints - 1) / kMaxFitPoints);
  std::vector<Eigen::Vector3f> fit;
  for (std::size_t k = 0; k < kept.size(); k += cap) fit.push_back(kept[k]);
  return PointCloud::Unorganized(std::move(fit));
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
  TakeSolution(*fit, o);
  o.points_used = fit->points_used;
  o.inliers = fit->inliers;
  o.correction_mm = fit->correction_mm;
  if (!fit->converged)
    o.failure = absl::StrCat("the best-fit did not converge in ", fit->iterations, " steps");
  return o;
}

}  // namespace

absl::StatusOr<AlignmentOutcome> MeasureAlignment(const AlignmentInputs& in,
                                                  const InspectionPlan& plan,
                                                  const std::atomic<bool>* cancel) {
  absl::StatusOr<AlignmentOutcome> measured = AlignmentOutcome{};
  tbb::task_arena(in.threads > 0 ? in.threads : tbb::task_arena::automatic).execute([&] {
    if (plan.alignment.mode == AlignmentMode::kRps) measured = MeasureRps(in, plan, cancel);
    if (plan.alignment.mode == AlignmentMode::kBestFit) measured = MeasureBestFit(in, plan, cancel);
  });
  ASSIGN_OR_RETURN(AlignmentOutcome o, std::move(measured));
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
