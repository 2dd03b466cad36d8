#include "core/plan/triangle_raster.h"

#include <Eigen/Geometry>
#include <cmath>

namespace surfinspect {
namespace {

constexpr std::size_t kMaxCells = std::size_t{1} << 22;  // per triangle; coarser beyond

}  // namespace

TriangleFrame::TriangleFrame(const TriangleMesh& part, uint32_t t) {
  const auto& tri = part.triangles[t];
  o = part.vertices[tri[0]].cast<double>();
  const Eigen::Vector3d b = part.vertices[tri[1]].cast<double>() - o,
                        c = part.vertices[tri[2]].cast<double>() - o;
  area = 0.5 * b.cross(c).norm();
  ok = area > 0 && std::isfinite(area);
  if (!ok) return;
  u = b.normalized();
  v = b.cross(c).cross(b).normalized();
  corner[0] = Eigen::Vector2d::Zero();
  corner[1] = {b.norm(), 0};
  corner[2] = {c.dot(u), c.dot(v)};
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector2d e = (corner[(k + 1) % 3] - corner[k]).normalized();
    outward[k] = {e.y(), -e.x()};
  }
  of = o.cast<float>();
  uf = u.cast<float>();
  vf = v.cast<float>();
}

TriangleRaster::TriangleRaster(const TriangleMesh& part, uint32_t t, double cell_mm, double reach)
    : f_(part, t), reach_(reach) {
  if (!f_.ok) {  // degenerate: one sample, never covered, weighing nothing
    occupied_.assign(1, 0);
    cells_.push_back(0);
    return;
  }
  const Eigen::Vector2d lo = f_.corner[0].cwiseMin(f_.corner[1]).cwiseMin(f_.corner[2]);
  const Eigen::Vector2d size = f_.corner[0].cwiseMax(f_.corner[1]).cwiseMax(f_.corner[2]) - lo;
  h_ = std::max({cell_mm, std::sqrt(size.x() * size.y() / kMaxCells), 1e-6});
  reach_cells_ = static_cast<int>(std::ceil(reach / h_));
  lo_ = lo - Eigen::Vector2d::Constant(reach_cells_ * h_);
  nx_ = static_cast<int>(std::ceil(size.x() / h_)) + 2 * reach_cells_;
  ny_ = static_cast<int>(std::ceil(size.y() / h_)) + 2 * reach_cells_;
  ListSamples();
  if (cells_.empty()) {  // smaller than a cell: its centroid's cell stands for it
    const Eigen::Vector2d g = (f_.corner[0] + f_.corner[1] + f_.corner[2]) / 3 - lo_;
    cells_.push_back(Index(static_cast<int>(g.x() / h_), static_cast<int>(g.y() / h_)));
  }
  occupied_.assign(static_cast<std::size_t>(nx_) * ny_, 0);
  inv_h_ = 1 / h_;
  const Eigen::Vector3d g = f_.At((f_.corner[1] + f_.corner[2]) / 3);
  centre_ = g.cast<float>();
  double r = 0;
  for (const auto& c : f_.corner) r = std::max(r, (f_.At(c) - g).norm());
  r += (reach_cells_ + 2) * h_;
  bound2_ = static_cast<float>(r * r);
  MakeStencils();
}

// The cells whose centres lie inside: per row, those around the span the
// edges' lines allow, each tested (the span's rounding adds or drops none).
void TriangleRaster::ListSamples() {
  const auto inside = [&](const Eigen::Vector2d& p) {
    for (int k = 0; k < 3; ++k)
      if (f_.Outside(p, k) > 0) return false;
    return true;
  };
  const double left = lo_.x() - h_, right = lo_.x() + (nx_ + 1) * h_;
  for (int iy = 0; iy < ny_; ++iy) {
    const double y = lo_.y() + h_ * (iy + 0.5);
    double x0 = left, x1 = right;
    for (int k = 0; k < 3; ++k) {  // inside edge k: n.x (x - c.x) + n.y (y - c.y) <= 0
      const Eigen::Vector2d &n = f_.outward[k], &c = f_.corner[k];
      const double rest = n.y() * (y - c.y());
      if (n.x() > 0) x1 = std::min(x1, c.x() - rest / n.x());
      if (n.x() < 0) x0 = std::max(x0, c.x() - rest / n.x());
      if (n.x() == 0 && rest > 0) x1 = left - h_;
    }
    if (!(x0 <= x1)) continue;
    const int a = std::max(0, static_cast<int>(std::floor((x0 - lo_.x()) / h_ - 0.5)) - 1);
    const int b = std::min(nx_ - 1, static_cast<int>(std::ceil((x1 - lo_.x()) / h_ - 0.5)) + 1);
    for (int ix = a; ix <= b; ++ix)
      if (inside(Centre(ix, iy))) cells_.push_back(Index(ix, iy));
  }
}

// Cell offsets (as index steps) by the farthest and the nearest a point in
// that cell can be from a sample's centre. A sample lies at least
// reach_cells_ from the grid's border, so no step leaves the grid.
void TriangleRaster::MakeStencils() {
  const double r = reach_ / h_;
  for (int dy = -reach_cells_; dy <= reach_cells_; ++dy)
    for (int dx = -reach_cells_; dx <= reach_cells_; ++dx) {
      const double ax = std::abs(dx), ay = std::abs(dy);
      const long step = static_cast<long>(dy) * nx_ + dx;
      if (std::hypot(ax + 0.5, ay + 0.5) <= r)
        sure_.push_back(step);
      else if (std::hypot(std::max(ax - 0.5, 0.0), std::max(ay - 0.5, 0.0)) <= r)
        maybe_.push_back(step);
    }
}

bool TriangleRaster::MaybeCovered(std::size_t c) const {
  const Eigen::Vector2d centre = Centre(static_cast<int>(c % nx_), static_cast<int>(c / nx_));
  for (long s : maybe_)
    for (int32_t i = head_[c + s]; i >= 0; i = next_[i])
      if ((points_[i].p - centre).squaredNorm() <= reach_ * reach_) return true;
  return false;
}

// Per cell its points as a linked list: head_[cell], then next_.
void TriangleRaster::ListPoints() {
  head_.assign(occupied_.size(), -1);
  next_.resize(points_.size());
  for (std::size_t i = 0; i < points_.size(); ++i) {
    next_[i] = head_[points_[i].cell];
    head_[points_[i].cell] = static_cast<int32_t>(i);
  }
}

}  // namespace surfinspect
