#include "core/plan/holes.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/plan/cad_holes.h"
#include "core/plan/profile_fit.h"
#include "core/plan/surface_neighbourhood.h"
#include "core/types/cancel.h"

namespace surfinspect {
namespace {

constexpr int kPlaneRounds = 5;
constexpr double kFaceSigmas = 4.0;      // a point within 4 sigma of the face is on it
constexpr double kMinFaceBandMm = 0.03;  // ... or within 30 um (an ideal, noiseless face)

struct View {
  const PlanView* plan = nullptr;
  PinholeRays rays;
  Eigen::Isometry3d sensor_from_part;
};

// The local face h = c0 + c1 u + c2 v in the hole's frame (h along its axis).
struct Face {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  double band_mm = 0;  // |h - face| within this is on the face
  double At(const Eigen::Vector2d& q) const { return c(0) + c(1) * q.x() + c(2) * q.y(); }
};

// A pixel of a view in the hole's window: its point in the hole's frame.
struct Pixel {
  Eigen::Vector2d q;  // in-plane
  double h = NAN;     // along the axis; NaN: no data
  double s = NAN;     // signed distance from the nominal edge (+ out of the hole)
};

struct Window {
  int col0 = 0, col1 = -1, row0 = 0, row1 = -1;  // inclusive
  int cols() const { return col1 - col0 + 1; }
  bool empty() const { return col1 < col0 || row1 < row0; }
};

ProfileFit NominalProfile(const PlanHole& h) {
  ProfileFit p;
  p.slot = h.slot;
  p.radius = 0.5 * h.diameter_mm;
  p.half_length = h.slot ? 0.5 * (h.length_mm - h.diameter_mm) : 0;
  return p;  // centre 0, direction e1: the hole's frame
}

// The pixels whose rays pass within `reach` of the nominal edge: the
// bounding box of the edge's offsets projected into the view, padded.
Window PixelWindow(const View& v, const PlaneFrame& f, const ProfileFit& nominal, double reach) {
  Window w{INT32_MAX, INT32_MIN, INT32_MAX, INT32_MIN};
  const double r = nominal.radius + reach;
  for (int k = 0; k < 64; ++k) {
    const double a = 2 * M_PI * k / 64;
    Eigen::Vector2d q(r * std::cos(a), r * std::sin(a));
    q.x() += q.x() >= 0 ? nominal.half_length : -nominal.half_length;
    Eigen::Vector2d px;
    if (!ProjectToPixel(v.rays, v.sensor_from_part * f.To3d(q), &px)) return Window{};
    w.col0 = std::min(w.col0, int(std::floor(px.x())) - 2);
    w.col1 = std::max(w.col1, int(std::ceil(px.x())) + 2);
    w.row0 = std::min(w.row0, int(std::floor(px.y())) - 2);
    w.row1 = std::max(w.row1, int(std::ceil(px.y())) + 2);
  }
  const PointCloud& g = *v.plan->grid_in_sensor;
  w.col0 = std::max(w.col0, 0);
  w.row0 = std::max(w.row0, 0);
  w.col1 = std::min(w.col1, int(g.width) - 1);
  w.row1 = std::min(w.row1, int(g.height) - 1);
  return w;
}

std::vector<Pixel> WindowPixels(const View& v, const Window& w, const PlaneFrame& f,
                                const ProfileFit& nominal) {
  std::vector<Pixel> out(std::size_t(w.cols()) * (w.row1 - w.row0 + 1));
  const PointCloud& g = *v.plan->grid_in_sensor;
  const Eigen::Isometry3d& part_from_sensor = v.plan->part_from_sensor;
  for (int row = w.row0; row <= w.row1; ++row)
    for (int col = w.col0; col <= w.col1; ++col) {
      const Eigen::Vector3f& p = g.points[std::size_t(row) * g.width + col];
      if (!PointCloud::IsValid(p)) continue;
      Pixel& px = out[std::size_t(row - w.row0) * w.cols() + (col - w.col0)];
      const Eigen::Vector3d x = part_from_sensor * p.cast<double>();
      px.q = f.To2d(x);
      px.h = (x - f.origin).dot(f.axis);
      px.s = ProfileDistance(nominal, px.q);
    }
  return out;
}

// A robust plane fit (3-sigma rejection rounds) to the sheet's points in
// the annulus 0 <= s <= reach, |h| <= max_h.
bool FitFace(const std::vector<const Pixel*>& pts, double max_h, Face* face) {
  std::vector<const Pixel*> use;
  for (const Pixel* p : pts)
    if (std::abs(p->h) <= max_h) use.push_back(p);
  for (int round = 0; round < kPlaneRounds; ++round) {
    if (use.size() < 10) return false;
    Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
    Eigen::Vector3d atb = Eigen::Vector3d::Zero();
    for (const Pixel* p : use) {
      const Eigen::Vector3d row(1, p->q.x(), p->q.y());
      ata += row * row.transpose();
      atb += row * p->h;
    }
    const Eigen::FullPivLU<Eigen::Matrix3d> lu(ata);
    if (!lu.isInvertible()) return false;
    face->c = lu.solve(atb);
    std::vector<double> abs_res;
    for (const Pixel* p : use) abs_res.push_back(std::abs(p->h - face->At(p->q)));
    const double sigma = 1.4826 * MedianInPlace(abs_res);
    face->band_mm = std::max(kFaceSigmas * sigma, kMinFaceBandMm);
    std::vector<const Pixel*> kept;
    for (const Pixel* p : use)
      if (std::abs(p->h - face->At(p->q)) <= face->band_mm) kept.push_back(p);
    if (kept.size() == use.size()) break;
    use = std::move(kept);
  }
  return true;
}

// Where the ray of pixel (col, row) meets the face, in the hole's plane.
bool MeetFace(const View& v, const PlaneFrame& f, const Face& face, int col, int row,
              Eigen::Vector2d* q) {
  const Eigen::Isometry3d& pfs = v.plan->part_from_sensor;
  const Eigen::Vector3d o = pfs.translation(), d = pfs.linear() * v.rays.Direction(col, row);
  const Eigen::Vector3d w = f.axis - face.c(1) * f.e1 - face.c(2) * f.e2;
  const double dw = d.dot(w);
  if (!(std::abs(dw) > 1e-12)) return false;
  const double t = (face.c(0) - (o - f.origin).dot(w)) / dw;
  if (!(t > 0)) return false;
  *q = f.To2d(o + t * d);
  return true;
}

struct Samples {
  std::vector<Eigen::Vector2d> points;
  std::vector<double> steps;  // per ray-pair sample: the pixels' distance on the face
  std::size_t wall = 0, views = 0;
};

// The edge and wall samples of one view (the header's steps 2 and 3).
void ViewSamples(const View& v, const Window& w, const std::vector<Pixel>& px, const PlaneFrame& f,
                 const Face& face, const ProfileFit& nominal, const HoleSettings& s, Samples* out) {
  const std::size_t before = out->points.size();
  auto at = [&](int col, int row) -> const Pixel& {
    return px[std::size_t(row - w.row0) * w.cols() + (col - w.col0)];
  };
  auto below = [&](const Pixel& p) { return p.h - face.At(p.q) < -face.band_mm; };
  auto on_face = [&](const Pixel& p) { return std::abs(p.h - face.At(p.q)) <= face.band_mm; };
  const int dc[4] = {1, -1, 0, 0}, dr[4] = {0, 0, 1, -1};
  for (int row = w.row0; row <= w.row1; ++row)
    for (int col = w.col0; col <= w.col1; ++col) {
      const Pixel& p = at(col, row);
      if (std::isnan(p.h) || !(std::abs(p.s) <= s.band_mm)) continue;
      if (below(p)) {
        if (p.h - face.At(p.q) >= -s.max_wall_mm) {
          out->points.push_back(p.q);
          ++out->wall;
        }
        continue;
      }
      if (!on_face(p)) continue;
      Eigen::Vector2d yp, yq;
      bool have_p = false;
      for (int k = 0; k < 4; ++k) {
        const int c = col + dc[k], r = row + dr[k];
        if (c < w.col0 || c > w.col1 || r < w.row0 || r > w.row1) continue;
        const Pixel& q = at(c, r);
        if (!std::isnan(q.h) && !below(q)) continue;  // on the face, or above it: no edge
        if (!have_p && !(have_p = MeetFace(v, f, face, col, row, &yp))) break;
        if (!MeetFace(v, f, face, c, r, &yq)) continue;
        if (!(ProfileDistance(nominal, yq) < ProfileDistance(nominal, yp))) continue;
        out->points.push_back(0.5 * (yp + yq));
        out->steps.push_back((yq - yp).norm());
      }
    }
  out->views += out->points.size() > before;
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

HoleMeasurement NotMeasured(std::string reason, const Samples& s) {
  HoleMeasurement m;
  m.reason = std::move(reason);
  m.samples = s.points.size();
  m.wall_points = s.wall;
  m.views = s.views;
  return m;
}

HoleMeasurement Judge(const PlanHole& hole, const PlaneFrame& f, const Samples& s,
                      const HoleSettings& settings) {
  if (s.points.size() < settings.min_samples)
    return NotMeasured(absl::StrCat(s.points.size(), " edge points found, at least ",
                                    settings.min_samples, " needed"),
                       s);
  const ProfileFit nominal = NominalProfile(hole);
  auto fit = hole.slot ? FitSlot2d(s.points, nominal) : FitCircle2d(s.points);
  if (!fit.ok()) return NotMeasured(std::string(fit.status().message()), s);
  std::vector<double> steps = s.steps;
  const double step = steps.empty() ? 0.0 : MedianInPlace(steps);
  const double max_gap = std::max(10 * M_PI / 180, 3 * step / std::max(fit->radius, 1e-6));
  HoleMeasurement m;
  m.samples = s.points.size();
  m.wall_points = s.wall;
  m.views = s.views;
  m.edge_points = fit->inliers;
  m.pixel_pitch_mm = step;
  m.arc_coverage_deg = ArcCoverageDeg(s.points, *fit, max_gap);
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

HoleMeasurement MeasureHole(const PlanHole& hole, const std::vector<View>& views,
                            const HoleSettings& s) {
  const PlaneFrame f = MakePlaneFrame(hole.position_mm, hole.axis, hole.direction);
  const ProfileFit nominal = NominalProfile(hole);
  const double reach = s.band_mm + s.annulus_mm;
  Samples samples;
  for (const View& v : views) {
    const Window w = PixelWindow(v, f, nominal, reach);
    if (w.empty()) continue;
    const std::vector<Pixel> px = WindowPixels(v, w, f, nominal);
    std::vector<const Pixel*> annulus;
    for (const Pixel& p : px)
      if (p.s >= 0 && p.s <= reach) annulus.push_back(&p);
    Face face;
    if (!FitFace(annulus, s.max_wall_mm, &face)) continue;
    ViewSamples(v, w, px, f, face, nominal, s, &samples);
  }
  return Judge(hole, f, samples, s);
}

}  // namespace

absl::StatusOr<std::vector<HoleMeasurement>> MeasureHoles(const std::vector<PlanHole>& holes,
                                                          const std::vector<PlanView>& views,
                                                          const HoleSettings& settings,
                                                          const std::atomic<bool>* cancel) {
  std::vector<View> models;
  for (const PlanView& pv : views) {
    if (pv.grid_in_sensor == nullptr) continue;
    auto rays = FitPinholeRays(*pv.grid_in_sensor);
    if (!rays.ok()) continue;  // an unorganized view has no edges to find
    models.push_back({&pv, *rays, pv.part_from_sensor.inverse()});
  }
  std::vector<HoleMeasurement> out;
  for (const PlanHole& hole : holes) {
    if (IsCancelled(cancel)) return absl::CancelledError("holes cancelled");
    if (models.empty()) {
      out.push_back(NotMeasured(views.empty() ? "no organized views (holes are measured by inspect)"
                                              : "no view has a pinhole's organized grid",
                                Samples{}));
      continue;
    }
    out.push_back(MeasureHole(hole, models, settings));
  }
  return out;
}

}  // namespace surfinspect
