#include "core/plan/coverage.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>

#include "core/types/cancel.h"

namespace surfinspect {
namespace {

constexpr std::size_t kMaxCells = std::size_t{1} << 22;  // per triangle; coarser beyond

// Compressed rows: row r is items[offsets[r] .. offsets[r + 1]).
template <typename T>
struct Rows {
  std::vector<uint32_t> offsets;
  std::vector<T> items;
};

// The matched closest points by their CAD triangle (a counting sort).
Rows<Eigen::Vector3f> PointsByTriangle(const ErrorMapResult& em, std::size_t triangles) {
  Rows<Eigen::Vector3f> r;
  r.offsets.assign(triangles + 1, 0);
  for (uint32_t t : em.triangle_id)
    if (t < triangles) ++r.offsets[t + 1];
  for (std::size_t t = 0; t < triangles; ++t) r.offsets[t + 1] += r.offsets[t];
  std::vector<uint32_t> next(r.offsets.begin(), r.offsets.end() - 1);
  r.items.resize(r.offsets.back());
  for (std::size_t i = 0; i < em.triangle_id.size(); ++i)
    if (em.triangle_id[i] < triangles) r.items[next[em.triangle_id[i]]++] = em.closest_point[i];
  return r;
}

// The triangles sharing an edge with each triangle.
Rows<uint32_t> EdgeNeighbours(const TriangleMesh& part) {
  const std::vector<EdgeUse> edges = SortedEdgeUses(part);
  std::vector<std::vector<uint32_t>> lists(part.num_triangles());
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].edge == edges[i].edge) ++j;
    for (std::size_t p = i; p < j; ++p)
      for (std::size_t q = i; q < j; ++q)
        if (edges[p].triangle != edges[q].triangle)
          lists[edges[p].triangle].push_back(edges[q].triangle);
    i = j;
  }
  Rows<uint32_t> r;
  r.offsets.push_back(0);
  for (const auto& l : lists) {
    r.items.insert(r.items.end(), l.begin(), l.end());
    r.offsets.push_back(static_cast<uint32_t>(r.items.size()));
  }
  return r;
}

// One triangle's sampling: a square grid of cells in its plane, the cells
// whose centres lie inside it standing for equal parts of its area. The
// grid has a margin of `reach` around the triangle, where the points of its
// neighbours land. A cell is covered when a point lies within reach of its
// centre. Two passes over the points: the first marks the cells holding
// one; the second covers exactly around the points whose cell is not
// enclosed by four such cells. Inside an occupied area each cell covers
// itself (its point is within half a diagonal of its centre), so the work
// is at the edges of what was seen and where the sampling is sparse.
class TriangleRaster {
 public:
  TriangleRaster(const TriangleMesh& part, uint32_t t, double cell_mm, double reach) {
    const auto& tri = part.triangles[t];
    o_ = part.vertices[tri[0]].cast<double>();
    const Eigen::Vector3d b = part.vertices[tri[1]].cast<double>() - o_,
                          c = part.vertices[tri[2]].cast<double>() - o_;
    area_ = 0.5 * b.cross(c).norm();
    if (!(area_ > 0) || !std::isfinite(area_)) {  // degenerate: one sample, never covered,
      state_.assign(1, 0);                        // weighing nothing
      cells_.push_back(0);
      return;
    }
    u_ = b.normalized();
    v_ = b.cross(c).cross(b).normalized();
    corner_[0] = Eigen::Vector2d::Zero();
    corner_[1] = {b.norm(), 0};
    corner_[2] = {c.dot(u_), c.dot(v_)};
    const Eigen::Vector2d lo = corner_[0].cwiseMin(corner_[1]).cwiseMin(corner_[2]);
    const Eigen::Vector2d size = corner_[0].cwiseMax(corner_[1]).cwiseMax(corner_[2]) - lo;
    h_ = std::max({cell_mm, std::sqrt(size.x() * size.y() / kMaxCells), 1e-6});
    reach_cells_ = static_cast<int>(std::ceil(reach / h_));
    lo_ = lo - Eigen::Vector2d::Constant(reach_cells_ * h_);
    nx_ = static_cast<int>(std::ceil(size.x() / h_)) + 2 * reach_cells_;
    ny_ = static_cast<int>(std::ceil(size.y() / h_)) + 2 * reach_cells_;
    for (int iy = 0; iy < ny_; ++iy)
      for (int ix = 0; ix < nx_; ++ix)
        if (Inside(Centre(ix, iy))) cells_.push_back(Index(ix, iy));
    if (cells_.empty()) {  // smaller than a cell: its centroid's cell stands for it
      const Eigen::Vector2d g = (corner_[0] + corner_[1] + corner_[2]) / 3 - lo_;
      cells_.push_back(Index(static_cast<int>(g.x() / h_), static_cast<int>(g.y() / h_)));
    }
    state_.assign(static_cast<std::size_t>(nx_) * ny_, 0);
    of_ = o_.cast<float>();
    uf_ = u_.cast<float>();
    vf_ = v_.cast<float>();
    inv_h_ = 1 / h_;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d e = (corner_[(k + 1) % 3] - corner_[k]).normalized();
      outward_[k] = {e.y(), -e.x()};
    }
    const Eigen::Vector3d g = o_ + (b + c) / 3;
    centre_ = g.cast<float>();
    const double r = std::max({(o_ - g).norm(), (o_ + b - g).norm(), (o_ + c - g).norm()}) +
                     (reach_cells_ + 2) * h_;
    bound2_ = static_cast<float>(r * r);
  }

  // A point projected on the plane, and its cell.
  struct Located {
    Eigen::Vector2d p;
    int cx, cy;
  };
  // False when q is off the grid or farther than `reach` from the triangle
  // (first by the grid's bounding sphere, a cheap test).
  bool Locate(const Eigen::Vector3f& q, double reach, Located& out) const {
    if ((q - centre_).squaredNorm() > bound2_) return false;
    // In float: relative to a corner, millimetres keep ~1e-5 mm here.
    const Eigen::Vector3f d = q - of_;
    out.p = Eigen::Vector2d(d.dot(uf_), d.dot(vf_));
    if (Beyond(out.p, reach)) return false;
    const double x = (out.p.x() - lo_.x()) * inv_h_, y = (out.p.y() - lo_.y()) * inv_h_;
    if (!(x >= 0 && y >= 0 && x < nx_ && y < ny_)) return false;
    out.cx = static_cast<int>(x);
    out.cy = static_cast<int>(y);
    return true;
  }
  void Occupy(const Located& l) { state_[Index(l.cx, l.cy)] = kOccupied; }

  // Covers the samples within reach of the point, unless its cell is
  // enclosed by occupied cells (their points cover what it would); call
  // after every point was occupied.
  void Cover(const Located& l, double reach) {
    if (Enclosed(l.cx, l.cy)) {
      state_[Index(l.cx, l.cy)] |= kCovered;  // within h / sqrt(2) < reach of its centre
      return;
    }
    // Row by row, the cells whose centres lie within reach: a span.
    const int y1 = std::min(ny_ - 1, l.cy + reach_cells_);
    for (int iy = std::max(0, l.cy - reach_cells_); iy <= y1; ++iy) {
      const double dy = lo_.y() + h_ * (iy + 0.5) - l.p.y();
      const double w2 = reach * reach - dy * dy;
      if (w2 < 0) continue;
      const double w = std::sqrt(w2), x = (l.p.x() - lo_.x()) / h_ - 0.5;
      const int x0 = std::max(0, static_cast<int>(std::ceil(x - w / h_)));
      const int x1 = std::min(nx_ - 1, static_cast<int>(std::floor(x + w / h_)));
      uint8_t* row = &state_[static_cast<std::size_t>(iy) * nx_];
      for (int ix = x0; ix <= x1; ++ix) row[ix] |= kCovered;
    }
  }

  // Calls f(3D location, covered) for each sample; returns their count.
  template <typename F>
  std::size_t ForEachSample(F&& f) const {
    for (std::size_t c : cells_)
      f(At(Centre(static_cast<int>(c % nx_), static_cast<int>(c / nx_))), state_[c] & kCovered);
    return cells_.size();
  }
  double area() const { return area_; }

 private:
  static constexpr uint8_t kOccupied = 1, kCovered = 2;

  std::size_t Index(int ix, int iy) const {
    return static_cast<std::size_t>(std::clamp(iy, 0, ny_ - 1)) * nx_ + std::clamp(ix, 0, nx_ - 1);
  }
  // All four edge neighbours occupied: its disc adds nothing they do not.
  // Wrong only for a disc reaching past an unoccupied cell behind them, which
  // an occupied neighbour within reach covers in turn.
  bool Enclosed(int ix, int iy) const {
    if (ix == 0 || iy == 0 || ix + 1 == nx_ || iy + 1 == ny_) return false;
    const std::size_t i = static_cast<std::size_t>(iy) * nx_ + ix;
    return state_[i - 1] & state_[i + 1] & state_[i - nx_] & state_[i + nx_] & kOccupied;
  }
  Eigen::Vector2d Centre(int ix, int iy) const {
    return lo_ + h_ * Eigen::Vector2d(ix + 0.5, iy + 0.5);
  }
  Eigen::Vector2d Project(const Eigen::Vector3f& q) const {
    const Eigen::Vector3d d = q.cast<double>() - o_;
    return {d.dot(u_), d.dot(v_)};
  }
  Eigen::Vector3d At(const Eigen::Vector2d& p) const { return o_ + p.x() * u_ + p.y() * v_; }
  // Farther than `reach` outside one of the edges' lines (a lower bound of
  // the distance to the triangle); the corners are counter-clockwise.
  bool Beyond(const Eigen::Vector2d& p, double reach) const {
    for (int k = 0; k < 3; ++k)
      if (outward_[k].dot(p - corner_[k]) > reach) return true;
    return false;
  }
  bool Inside(const Eigen::Vector2d& p) const {  // the corners are counter-clockwise
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d e = corner_[(k + 1) % 3] - corner_[k], w = p - corner_[k];
      if (e.x() * w.y() - e.y() * w.x() < 0) return false;
    }
    return true;
  }

  Eigen::Vector3d o_ = Eigen::Vector3d::Zero(), u_ = Eigen::Vector3d::UnitX(),
                  v_ = Eigen::Vector3d::UnitY();
  Eigen::Vector2d corner_[3], lo_ = Eigen::Vector2d::Zero(), outward_[3];  // unit edge normals
  Eigen::Vector3f centre_ = Eigen::Vector3f::Zero();  // the bounding sphere of the grid's reach
  Eigen::Vector3f of_, uf_, vf_;                      // o_, u_, v_ in float, for the points
  double inv_h_ = 1;
  float bound2_ = -1;  // < 0: no point is near (a degenerate triangle)
  double h_ = 1, area_ = 0;
  int nx_ = 1, ny_ = 1, reach_cells_ = 0;
  std::vector<std::size_t> cells_;
  std::vector<uint8_t> state_;
};

// Per-triangle results: covered fraction, and per reachable comparison
// point (indexed like plan.point_ids) the area within its radius and of it
// covered.
struct TriangleSums {
  std::vector<float> covered;
  std::vector<double> point_area, point_covered;
};

// Triangle t sampled and covered by the points on it and on the triangles
// sharing its edges (so coverage runs across an edge as on the surface).
void SampleTriangle(const TriangleMesh& part, const ResolvedInspectionPlan& rp,
                    const Rows<Eigen::Vector3f>& points, const Rows<uint32_t>& neighbours,
                    const CoverageSettings& s, uint32_t t, TriangleSums& out) {
  // A comparison point's disc gets samples however small it is: its
  // triangles are sampled at a third of the smallest radius reaching them.
  double cell = s.sample_mm;
  for (uint32_t k = rp.point_offsets[t]; k < rp.point_offsets[t + 1]; ++k)
    cell = std::min(cell, rp.plan.points[rp.point_ids[k]].radius_mm / 3);
  TriangleRaster raster(part, t, cell, s.distance_mm);
  std::vector<TriangleRaster::Located> located;
  TriangleRaster::Located l;
  const auto locate = [&](uint32_t tri) {
    for (uint32_t k = points.offsets[tri]; k < points.offsets[tri + 1]; ++k)
      if (raster.Locate(points.items[k], s.distance_mm, l)) located.push_back(l);
  };
  locate(t);
  for (uint32_t k = neighbours.offsets[t]; k < neighbours.offsets[t + 1]; ++k)
    locate(neighbours.items[k]);
  for (const auto& p : located) raster.Occupy(p);
  for (const auto& p : located) raster.Cover(p, s.distance_mm);
  const uint32_t first = rp.point_offsets[t], last = rp.point_offsets[t + 1];
  std::size_t covered = 0;
  std::vector<std::pair<std::size_t, bool>> near;  // (row k, covered) per sample in a point's disc
  const std::size_t samples = raster.ForEachSample([&](const Eigen::Vector3d& q, bool hit) {
    covered += hit;
    for (uint32_t k = first; k < last; ++k) {
      const ComparisonPoint& p = rp.plan.points[rp.point_ids[k]];
      if ((q - p.position_mm).squaredNorm() <= p.radius_mm * p.radius_mm) near.emplace_back(k, hit);
    }
  });
  const double sample_area = raster.area() / static_cast<double>(samples);
  for (const auto& [k, hit] : near) {
    out.point_area[k] += sample_area;
    out.point_covered[k] += hit ? sample_area : 0;
  }
  out.covered[t] = static_cast<float>(static_cast<double>(covered) / static_cast<double>(samples));
}

double Fraction(double covered, double area) { return area > 0 ? covered / area : 0; }

}  // namespace

absl::StatusOr<CoverageResult> ComputeCoverage(const ErrorMapResult& em, const TriangleMesh& part,
                                               const ResolvedInspectionPlan& rp,
                                               const CoverageSettings& settings,
                                               const std::atomic<bool>* cancel) {
  CoverageSettings s = settings;
  if (!(s.distance_mm > 0) || !std::isfinite(s.distance_mm) || !(s.sample_mm >= 0))
    return absl::InvalidArgumentError("coverage: distance_mm must be > 0, sample_mm >= 0");
  if (s.sample_mm == 0) s.sample_mm = s.distance_mm / 2;
  if (rp.num_triangles != part.num_triangles() || em.closest_point.size() != em.triangle_id.size())
    return absl::InvalidArgumentError("coverage: the plan, the part and the error map differ");
  const Rows<Eigen::Vector3f> points = PointsByTriangle(em, part.num_triangles());
  const Rows<uint32_t> neighbours = EdgeNeighbours(part);
  TriangleSums sums{std::vector<float>(part.num_triangles(), 0.f),
                    std::vector<double>(rp.point_ids.size(), 0),
                    std::vector<double>(rp.point_ids.size(), 0)};
  tbb::task_arena arena(s.threads > 0 ? s.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, rp.num_triangles, 64), [&](auto range) {
      if (IsCancelled(cancel)) return;
      for (uint32_t t = range.begin(); t != range.end(); ++t)
        SampleTriangle(part, rp, points, neighbours, s, t, sums);
    });
  });
  if (IsCancelled(cancel)) return absl::CancelledError("coverage cancelled");
  CoverageResult out;
  out.distance_mm = s.distance_mm;
  out.sample_mm = s.sample_mm;
  std::vector<double> area;
  for (const auto& tri : part.triangles)
    area.push_back(0.5 * (part.vertices[tri[1]] - part.vertices[tri[0]])
                             .cast<double>()
                             .cross((part.vertices[tri[2]] - part.vertices[tri[0]]).cast<double>())
                             .norm());
  std::vector<double> region_area(rp.plan.regions.size(), 0), region_cov(region_area.size(), 0);
  double total = 0, total_cov = 0;
  for (uint32_t t = 0; t < rp.num_triangles; ++t) {
    total += area[t];
    total_cov += area[t] * sums.covered[t];
    for (uint32_t k = rp.region_offsets[t]; k < rp.region_offsets[t + 1]; ++k) {
      region_area[rp.region_ids[k]] += area[t];
      region_cov[rp.region_ids[k]] += area[t] * sums.covered[t];
    }
  }
  out.surface = Fraction(total_cov, total);
  for (std::size_t r = 0; r < region_area.size(); ++r)
    out.regions.push_back(Fraction(region_cov[r], region_area[r]));
  std::vector<double> point_area(rp.plan.points.size(), 0), point_cov(point_area.size(), 0);
  for (std::size_t k = 0; k < rp.point_ids.size(); ++k) {
    point_area[rp.point_ids[k]] += sums.point_area[k];
    point_cov[rp.point_ids[k]] += sums.point_covered[k];
  }
  for (std::size_t p = 0; p < point_area.size(); ++p)
    out.points.push_back(Fraction(point_cov[p], point_area[p]));
  out.triangles = std::move(sums.covered);
  return out;
}

}  // namespace surfinspect
