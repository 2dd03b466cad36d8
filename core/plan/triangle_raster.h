// One CAD triangle sampled for coverage (core/plan/coverage.h): a square
// grid of cells in the triangle's plane, the cells whose centres lie inside
// it standing for equal parts of its area. The grid has a margin of `reach`
// around the triangle, where the points of its neighbours land. A sample is
// covered when a point lies within reach of its centre.
//
// The points are placed per cell, and each sample looks at the cells around
// it. A cell whose every point is within reach (the "sure" stencil) decides
// by being occupied; a cell only partly within reach (the "maybe" stencil)
// by its points' distances. Inside an occupied area the first look decides,
// so the exact work is at the edges of what was seen: the points are listed
// per cell only when a sample needs them. Units mm.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/types/triangle_mesh.h"

namespace surfinspect {

// A triangle's plane: corner 0 at the origin, u along edge 0, the corners
// counter-clockwise. Degenerate (zero or non-finite area): !ok.
struct TriangleFrame {
  TriangleFrame(const TriangleMesh& part, uint32_t t);
  // In float: relative to a corner, millimetres keep ~1e-5 mm here.
  Eigen::Vector2d Project(const Eigen::Vector3f& q) const {
    const Eigen::Vector3f d = q - of;
    return {d.dot(uf), d.dot(vf)};
  }
  // Signed distance of p outside edge k's line (negative inside).
  double Outside(const Eigen::Vector2d& p, int k) const { return outward[k].dot(p - corner[k]); }
  Eigen::Vector3d At(const Eigen::Vector2d& p) const { return o + p.x() * u + p.y() * v; }

  bool ok = false;
  double area = 0;
  Eigen::Vector3d o = Eigen::Vector3d::Zero(), u = Eigen::Vector3d::UnitX(),
                  v = Eigen::Vector3d::UnitY();
  Eigen::Vector2d corner[3], outward[3];  // outward: unit edge normals in the plane
  Eigen::Vector3f of, uf, vf;             // o, u, v in float, for the points
};

class TriangleRaster {
 public:
  // Triangle t of `part`, sampled every cell_mm (coarser for a huge
  // triangle: at most 2^22 cells), covered within `reach` mm.
  TriangleRaster(const TriangleMesh& part, uint32_t t, double cell_mm, double reach);

  // Decides every sample not yet covered. feed(add) calls add(q, own) for
  // each point q that may cover the triangle; `own`: q is a closest point
  // on this triangle, so on the grid. The points are fed once to mark the
  // occupied cells, and again, listed per cell, only if a sample is left
  // undecided. Called again with more points, it decides the samples still
  // uncovered (those the earlier points did not reach).
  template <typename Feed>
  void Cover(Feed&& feed) {
    feed([this](const Eigen::Vector3f& q, bool own) {
      std::size_t c;
      if (Place(q, own, nullptr, &c)) occupied_[c] = 1;
    });
    if (hit_.empty()) hit_.assign(cells_.size(), 0);
    bool undecided = false;
    for (std::size_t j = 0; j < cells_.size(); ++j)
      if (!hit_[j]) undecided |= !(hit_[j] = SurelyCovered(cells_[j]));
    if (!undecided || !f_.ok) return;
    points_.clear();
    feed([this](const Eigen::Vector3f& q, bool own) {
      Eigen::Vector2d p;
      std::size_t c;
      if (Place(q, own, &p, &c)) points_.push_back({p, static_cast<uint32_t>(c)});
    });
    ListPoints();
    for (std::size_t j = 0; j < cells_.size(); ++j)
      if (!hit_[j]) hit_[j] = MaybeCovered(cells_[j]);
  }

  // Calls f(3D location, covered) for each sample, after Cover.
  template <typename F>
  void ForEachSample(F&& f) const {
    for (std::size_t j = 0; j < cells_.size(); ++j)
      f(f_.At(Centre(static_cast<int>(cells_[j] % nx_), static_cast<int>(cells_[j] / nx_))),
        hit_[j] != 0);
  }
  std::size_t CountCovered() const {
    return static_cast<std::size_t>(std::count(hit_.begin(), hit_.end(), 1));
  }
  bool AllCovered() const { return CountCovered() == cells_.size(); }
  std::size_t samples() const { return cells_.size(); }
  bool ok() const { return f_.ok; }  // false: degenerate, one sample never covered
  double area() const { return f_.area; }

 private:
  void ListSamples();
  void MakeStencils();
  bool MaybeCovered(std::size_t c) const;
  void ListPoints();
  std::size_t Index(int ix, int iy) const {
    return static_cast<std::size_t>(std::clamp(iy, 0, ny_ - 1)) * nx_ + std::clamp(ix, 0, nx_ - 1);
  }
  Eigen::Vector2d Centre(int ix, int iy) const {
    return lo_ + h_ * Eigen::Vector2d(ix + 0.5, iy + 0.5);
  }
  // q's place on the grid: its cell (and in-plane point), false when it
  // lies off the grid or beyond reach of the triangle (first tested by the
  // grid's bounding sphere, a cheap test).
  bool Place(const Eigen::Vector3f& q, bool own, Eigen::Vector2d* in_plane, std::size_t* c) const {
    if (!f_.ok || (!own && (q - centre_).squaredNorm() > bound2_)) return false;
    const Eigen::Vector2d p = f_.Project(q);
    if (!own)
      for (int k = 0; k < 3; ++k)
        if (f_.Outside(p, k) > reach_) return false;
    const double x = (p.x() - lo_.x()) * inv_h_, y = (p.y() - lo_.y()) * inv_h_;
    if (!(x >= 0 && y >= 0 && x < nx_ && y < ny_)) return false;
    *c = static_cast<std::size_t>(y) * nx_ + static_cast<std::size_t>(x);
    if (in_plane) *in_plane = p;
    return true;
  }
  bool SurelyCovered(std::size_t c) const {
    if (!f_.ok) return false;
    for (long s : sure_)
      if (occupied_[c + s]) return true;
    return false;
  }

  TriangleFrame f_;
  double reach_, h_ = 1, inv_h_ = 1;
  Eigen::Vector2d lo_ = Eigen::Vector2d::Zero();
  Eigen::Vector3f centre_ = Eigen::Vector3f::Zero();  // the bounding sphere of the grid's reach
  float bound2_ = -1;  // < 0: no point is near (a degenerate triangle)
  int nx_ = 1, ny_ = 1, reach_cells_ = 0;
  std::vector<std::size_t> cells_;  // the samples
  std::vector<long> sure_, maybe_;
  struct InPlane {
    Eigen::Vector2d p;
    uint32_t cell;
  };
  std::vector<InPlane> points_;
  std::vector<uint8_t> occupied_;  // per cell: a point lies in it
  std::vector<uint8_t> hit_;       // per sample: covered
  // Once needed: per cell its last point, per point the one before.
  std::vector<int32_t> head_, next_;
};

}  // namespace surfinspect
