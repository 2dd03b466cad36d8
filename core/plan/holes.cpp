#include "core/plan/holes.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/plan/profile_fit.h"
#include "core/types/cancel.h"

namespace surfinspect {
namespace {

constexpr std::size_t kMinSamples = 12;
// A hole fewer pixels across than this is not measured: its edge samples
// scatter by half a pitch each and a few dozen of them cannot pin a centre
// or a diameter to a fifth of a pixel (measured: on a 2 mm pitch, the demo's
// 5-12 mm holes gave true positions scattered far beyond the sensor's
// noise).
constexpr double kMinPixelsAcross = 8;

ProfileFit NominalProfile(const PlanHole& h) {
  return NominalContour(h.slot, h.diameter_mm, h.length_mm);  // in the hole's frame
}

// The arc of the edge the kept samples cover, seen from the fitted centre:
// gaps between neighbouring samples count up to `max_gap` (a few pixel
// steps), larger gaps are unseen.
double ArcCoverageDeg(const std::vector<Eigen::Vector2d>& pts, const ProfileFit& fit,
                      double max_gap) {
  std::vector<double> angle;
  for (std::size_t i = 0; i < pts.size(); ++i)
    if (fit.inlier[i])
      angle.push_back(std::atan2(pts[i].y() - fit.centre.y(), pts[i].x() - fit.centre.x()));
  if (angle.size() < 2) return 0;
  std::sort(angle.begin(), angle.end());
  double covered = std::min(angle.front() + 2 * M_PI - angle.back(), max_gap);
  for (std::size_t i = 1; i < angle.size(); ++i)
    covered += std::min(angle[i] - angle[i - 1], max_gap);
  return covered * 180 / M_PI;
}

HoleMeasurement NotMeasured(std::string reason, const EdgeSamples& s) {
  HoleMeasurement m;
  m.reason = std::move(reason);
  m.samples = s.points.size();
  m.wall_points = s.wall;
  m.views = s.views;
  return m;
}

HoleMeasurement Judge(const PlanHole& hole, const PlaneFrame& f, const EdgeSamples& s) {
  if (s.points.size() < kMinSamples)
    return NotMeasured(
        absl::StrCat(s.points.size(), " edge points found, at least ", kMinSamples, " needed"), s);
  const ProfileFit nominal = NominalProfile(hole);
  auto fit = hole.slot ? FitSlot2d(s.points, nominal) : FitCircle2d(s.points);
  if (!fit.ok()) return NotMeasured(std::string(fit.status().message()), s);
  const double step = s.steps.empty() ? 0.0 : s.PixelPitch();
  const double max_gap = std::max(10 * M_PI / 180, 3 * step / std::max(fit->radius, 1e-6));
  HoleMeasurement m;
  m.samples = s.points.size();
  m.wall_points = s.wall;
  m.views = s.views;
  m.edge_points = fit->inliers;
  m.pixel_pitch_mm = step;
  m.arc_coverage_deg = ArcCoverageDeg(s.points, *fit, max_gap);
  if (hole.diameter_mm < kMinPixelsAcross * step) {
    m.reason =
        absl::StrFormat("%.3g mm across is %.1f pixels at a %.3g mm pitch, at least %.0f needed",
                        hole.diameter_mm, hole.diameter_mm / step, step, kMinPixelsAcross);
    return m;
  }
  if (m.arc_coverage_deg < hole.min_arc_deg) {
    m.reason = absl::StrFormat("edge seen over %.0f deg, at least %.0f needed", m.arc_coverage_deg,
                               hole.min_arc_deg);
    return m;
  }
  m.measured = true;
  m.measured_position_mm = f.To3d(fit->centre);
  m.position_deviation_mm = m.measured_position_mm - f.origin;
  m.true_position_mm = 2 * fit->centre.norm();
  m.diameter_mm = fit->diameter();
  m.diameter_deviation_mm = m.diameter_mm - hole.diameter_mm;
  if (hole.slot) {
    m.length_mm = fit->length();
    m.length_deviation_mm = m.length_mm - hole.length_mm;
  }
  m.form_mm = fit->form;
  m.rms_mm = fit->rms;
  return m;
}

// The hole's contour (+ into the material: outside the hole) and an
// outline `reach` beyond it all round, in the hole's frame.
EdgeContour ContourOf(const PlanHole& hole, double reach) {
  EdgeContour c;
  c.frame = MakePlaneFrame(hole.position_mm, hole.axis, hole.direction);
  const ProfileFit nominal = NominalProfile(hole);
  c.into_material = [nominal](const Eigen::Vector2d& q) { return ProfileDistance(nominal, q); };
  const double r = nominal.radius + reach;
  for (int k = 0; k < 64; ++k) {
    const double a = 2 * M_PI * k / 64;
    Eigen::Vector2d q(r * std::cos(a), r * std::sin(a));
    q.x() += q.x() >= 0 ? nominal.half_length : -nominal.half_length;
    c.outline.push_back(q);
  }
  return c;
}

}  // namespace

absl::StatusOr<std::vector<HoleMeasurement>> MeasureHoles(const std::vector<PlanHole>& holes,
                                                          const std::vector<PlanView>& views,
                                                          const EdgeSettings& settings,
                                                          const std::atomic<bool>* cancel,
                                                          const std::vector<RayView>* prepared) {
  const std::vector<RayView> own = prepared ? std::vector<RayView>{} : PrepareRayViews(views);
  const std::vector<RayView>& rays = prepared ? *prepared : own;
  if (rays.empty())
    return std::vector<HoleMeasurement>(
        holes.size(),
        NotMeasured(views.empty() ? "no organized views (holes are measured by inspect)"
                                  : "no view has a pinhole's organized grid",
                    EdgeSamples{}));
  // Each hole reads its own window of pixels: in parallel (the caller's
  // arena), each result in its slot.
  std::vector<HoleMeasurement> out(holes.size());
  tbb::parallel_for(std::size_t{0}, holes.size(), [&](std::size_t i) {
    if (IsCancelled(cancel)) return;
    const EdgeContour c = ContourOf(holes[i], settings.band_mm + settings.annulus_mm);
    out[i] = Judge(holes[i], c.frame, SampleEdge(rays, c, settings));
  });
  if (IsCancelled(cancel)) return absl::CancelledError("holes cancelled");
  return out;
}

}  // namespace surfinspect
