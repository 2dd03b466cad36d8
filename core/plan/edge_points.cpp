#include "core/plan/edge_points.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/plan/surface_neighbourhood.h"
#include "core/types/cancel.h"

namespace surfinspect {
namespace {

constexpr std::size_t kMinSamples = 12;
constexpr double kRejectSigmas = 3.0;

// The edge's frame at the CAD edge: e1 along it, e2 across; + into the
// material is against `outward`.
EdgeContour ContourOf(const CadEdge& edge, double radius, double reach) {
  EdgeContour c;
  c.frame = MakePlaneFrame(edge.point_mm, edge.normal, edge.tangent);
  const double sign = c.frame.e2.dot(edge.outward) > 0 ? -1.0 : 1.0;
  c.into_material = [sign](const Eigen::Vector2d& q) { return sign * q.y(); };
  for (double u : {-(radius + reach), radius + reach})
    for (double v : {-reach, reach}) c.outline.emplace_back(u, v);
  return c;
}

// The mean offset (+ off the material) of the samples within +-radius
// along the edge, after a 3-sigma (robust) rejection.
EdgePointMeasurement Judge(const EdgeContour& c, const EdgeSamples& s, double radius) {
  EdgePointMeasurement m;
  m.views = s.views;
  m.pixel_pitch_mm = s.steps.empty() ? NAN : s.PixelPitch();
  std::vector<double> off;
  for (const Eigen::Vector2d& q : s.points)
    if (std::abs(q.x()) <= radius) off.push_back(-c.into_material(q));
  if (off.size() < kMinSamples) {
    m.reason = absl::StrCat(off.size(), " edge points found, at least ", kMinSamples, " needed");
    return m;
  }
  std::vector<double> copy = off;
  const double median = MedianInPlace(copy);
  std::vector<double> abs_dev;
  for (double d : off) abs_dev.push_back(std::abs(d - median));
  const double limit = std::max(kRejectSigmas * MadSigma(abs_dev), 1e-3);
  double sum = 0;
  for (double d : off)
    if (std::abs(d - median) <= limit) sum += d, ++m.points;
  m.value_mm = sum / double(m.points);
  m.measured = true;
  return m;
}

}  // namespace

absl::StatusOr<std::vector<EdgePointMeasurement>> MeasureEdgePoints(
    const std::vector<PlanEdgePoint>& points, const TriangleMesh& part,
    const std::vector<PlanView>& views, const EdgeSettings& settings,
    const std::atomic<bool>* cancel, const std::vector<RayView>* prepared) {
  const std::vector<RayView> own =
      points.empty() || prepared ? std::vector<RayView>{} : PrepareRayViews(views);
  const std::vector<RayView>& rays = prepared ? *prepared : own;
  std::vector<EdgePointMeasurement> out;
  for (const PlanEdgePoint& p : points) {
    if (IsCancelled(cancel)) return absl::CancelledError("edge points cancelled");
    EdgePointMeasurement m;
    const std::optional<CadEdge> edge = NearestBoundaryEdge(part, p.position_mm);
    if (rays.empty() || !edge) {
      m.reason = !edge           ? "the CAD has no boundary there"
                 : views.empty() ? "no organized views (edges are measured by inspect)"
                                 : "no view has a pinhole's organized grid";
      out.push_back(m);
      continue;
    }
    const EdgeContour c = ContourOf(*edge, p.radius_mm, settings.band_mm + settings.annulus_mm);
    out.push_back(Judge(c, SampleEdge(rays, c, settings), p.radius_mm));
  }
  return out;
}

}  // namespace surfinspect
