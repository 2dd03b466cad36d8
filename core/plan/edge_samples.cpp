#include "core/plan/edge_samples.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "core/plan/surface_neighbourhood.h"

namespace surfinspect {
namespace {

constexpr int kPlaneRounds = 5;
constexpr double kFaceSigmas = 4.0;      // a point within 4 sigma of the face is on it
constexpr double kMinFaceBandMm = 0.03;  // ... or within 30 um (an ideal, noiseless face)

// The local face h = c0 + c1 u + c2 v in the contour's frame (h along its axis).
struct Face {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  double band_mm = 0;  // |h - face| within this is on the face
  double At(const Eigen::Vector2d& q) const { return c(0) + c(1) * q.x() + c(2) * q.y(); }
};

// A pixel of a view in the window: its point in the contour's frame.
struct Pixel {
  Eigen::Vector2d q;  // in-plane
  double h = NAN;     // along the axis; NaN: no data
  double s = NAN;     // signed distance from the nominal edge (+ into the material)
};

struct Window {
  int col0 = 0, col1 = -1, row0 = 0, row1 = -1;  // inclusive
  int cols() const { return col1 - col0 + 1; }
  bool empty() const { return col1 < col0 || row1 < row0; }
};

// The bounding box of the outline projected into the view, padded.
Window PixelWindow(const RayView& v, const EdgeContour& c) {
  Window w{INT32_MAX, INT32_MIN, INT32_MAX, INT32_MIN};
  for (const Eigen::Vector2d& q : c.outline) {
    Eigen::Vector2d px;
    if (!ProjectToPixel(v.rays, v.sensor_from_part * c.frame.To3d(q), &px)) return Window{};
    w.col0 = std::min(w.col0, int(std::floor(px.x())) - 2);
    w.col1 = std::max(w.col1, int(std::ceil(px.x())) + 2);
    w.row0 = std::min(w.row0, int(std::floor(px.y())) - 2);
    w.row1 = std::max(w.row1, int(std::ceil(px.y())) + 2);
  }
  const PointCloud& g = *v.view->grid_in_sensor;
  w.col0 = std::max(w.col0, 0);
  w.row0 = std::max(w.row0, 0);
  w.col1 = std::min(w.col1, int(g.width) - 1);
  w.row1 = std::min(w.row1, int(g.height) - 1);
  return w;
}

std::vector<Pixel> WindowPixels(const RayView& v, const Window& w, const EdgeContour& c) {
  std::vector<Pixel> out(std::size_t(w.cols()) * (w.row1 - w.row0 + 1));
  const PointCloud& g = *v.view->grid_in_sensor;
  const Eigen::Isometry3d& part_from_sensor = v.view->part_from_sensor;
  for (int row = w.row0; row <= w.row1; ++row)
    for (int col = w.col0; col <= w.col1; ++col) {
      const Eigen::Vector3f& p = g.points[std::size_t(row) * g.width + col];
      if (!PointCloud::IsValid(p)) continue;
      Pixel& px = out[std::size_t(row - w.row0) * w.cols() + (col - w.col0)];
      const Eigen::Vector3d x = part_from_sensor * p.cast<double>();
      px.q = c.frame.To2d(x);
      px.h = (x - c.frame.origin).dot(c.frame.axis);
      px.s = c.into_material(px.q);
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
    const double sigma = MadSigma(abs_res);
    face->band_mm = std::max(kFaceSigmas * sigma, kMinFaceBandMm);
    std::vector<const Pixel*> kept;
    for (const Pixel* p : use)
      if (std::abs(p->h - face->At(p->q)) <= face->band_mm) kept.push_back(p);
    if (kept.size() == use.size()) break;
    use = std::move(kept);
  }
  return true;
}

// Where the ray of pixel (col, row) meets the face, in the contour's plane.
bool MeetFace(const RayView& v, const PlaneFrame& f, const Face& face, int col, int row,
              Eigen::Vector2d* q) {
  const Eigen::Isometry3d& pfs = v.view->part_from_sensor;
  const Eigen::Vector3d o = pfs.translation(), d = pfs.linear() * v.rays.Direction(col, row);
  const Eigen::Vector3d w = f.axis - face.c(1) * f.e1 - face.c(2) * f.e2;
  const double dw = d.dot(w);
  if (!(std::abs(dw) > 1e-12)) return false;
  const double t = (face.c(0) - (o - f.origin).dot(w)) / dw;
  if (!(t > 0)) return false;
  *q = f.To2d(o + t * d);
  return true;
}

// The edge and wall samples of one view (the header's steps 2 and 3).
void ViewSamples(const RayView& v, const Window& w, const std::vector<Pixel>& px,
                 const EdgeContour& c, const Face& face, const EdgeSettings& s, EdgeSamples* out) {
  const PlaneFrame& f = c.frame;
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
        const int qc = col + dc[k], qr = row + dr[k];
        if (qc < w.col0 || qc > w.col1 || qr < w.row0 || qr > w.row1) continue;
        const Pixel& q = at(qc, qr);
        if (!std::isnan(q.h) && !below(q)) continue;  // on the face, or above it: no edge
        if (!have_p && !(have_p = MeetFace(v, f, face, col, row, &yp))) break;
        if (!MeetFace(v, f, face, qc, qr, &yq)) continue;
        if (!(c.into_material(yq) < c.into_material(yp))) continue;
        out->points.push_back(0.5 * (yp + yq));
        out->steps.push_back((yq - yp).norm());
      }
    }
  out->views += out->points.size() > before;
}

}  // namespace

std::vector<RayView> PrepareRayViews(const std::vector<PlanView>& views) {
  std::vector<RayView> out;
  for (const PlanView& pv : views) {
    if (pv.grid_in_sensor == nullptr) continue;
    auto rays = FitPinholeRays(*pv.grid_in_sensor);
    if (rays.ok()) out.push_back({&pv, *rays, pv.part_from_sensor.inverse()});
  }
  return out;
}

double EdgeSamples::PixelPitch() const {
  std::vector<double> copy = steps;
  return MedianInPlace(copy);
}

EdgeSamples SampleEdge(const std::vector<RayView>& views, const EdgeContour& c,
                       const EdgeSettings& s) {
  const double reach = s.band_mm + s.annulus_mm;
  EdgeSamples samples;
  for (const RayView& v : views) {
    const Window w = PixelWindow(v, c);
    if (w.empty()) continue;
    const std::vector<Pixel> px = WindowPixels(v, w, c);
    std::vector<const Pixel*> material;
    for (const Pixel& p : px)
      if (p.s >= 0 && p.s <= reach) material.push_back(&p);
    Face face;
    if (FitFace(material, s.max_wall_mm, &face)) ViewSamples(v, w, px, c, face, s, &samples);
  }
  return samples;
}

}  // namespace surfinspect
