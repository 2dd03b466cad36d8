#include "core/plan/coverage.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/types/cancel.h"

namespace surfinspect {
namespace {

constexpr std::size_t kMaxCells = std::size_t{1} << 22;  // per triangle; coarser beyond

// A triangle across an edge: its index and which of its edges (k: corner k
// to corner k + 1) is the shared one.
struct Neighbour {
  uint32_t triangle;
  uint8_t edge;
};
// Triangle t's neighbours: items[offsets[t] .. offsets[t + 1]).
struct Neighbours {
  std::vector<uint32_t> offsets;
  std::vector<Neighbour> items;
};

uint8_t EdgeIndex(const TriangleMesh& part, uint32_t t, uint64_t key) {
  const auto& v = part.triangles[t];  // the key is SortedEdgeUses': low id << 32 | high id
  for (uint8_t k = 0; k < 2; ++k)
    if (key == (uint64_t{std::min(v[k], v[k + 1])} << 32 | std::max(v[k], v[k + 1]))) return k;
  return 2;
}

// The triangles sharing an edge with each triangle.
Neighbours EdgeNeighbours(const TriangleMesh& part) {
  const std::vector<EdgeUse> edges = SortedEdgeUses(part);
  std::vector<std::vector<Neighbour>> lists(part.num_triangles());
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].edge == edges[i].edge) ++j;
    for (std::size_t p = i; p < j; ++p)
      for (std::size_t q = i; q < j; ++q)
        if (edges[p].triangle != edges[q].triangle)
          lists[edges[p].triangle].push_back(
              {edges[q].triangle, EdgeIndex(part, edges[q].triangle, edges[q].edge)});
    i = j;
  }
  Neighbours r;
  r.offsets.push_back(0);
  for (const auto& l : lists) {
    r.items.insert(r.items.end(), l.begin(), l.end());
    r.offsets.push_back(static_cast<uint32_t>(r.items.size()));
  }
  return r;
}

// A triangle's plane: corner 0 at the origin, u along edge 0, the corners
// counter-clockwise. Degenerate (zero or non-finite area): !ok.
struct TriangleFrame {
  TriangleFrame(const TriangleMesh& part, uint32_t t) {
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

// Per point of `points` (same order): bit k set when the point lies within
// `reach` of its triangle's edge k line, in the triangle's plane. Only such
// points can cover the neighbour across edge k: on a flat or gently bent
// surface the neighbour lies beyond that line; across a sharp fold a point
// deep in its face no longer reaches the other face's edge by projection.
std::vector<uint8_t> NearEdges(const TriangleMesh& part, const ErrorMapResult& em,
                               const TrianglePoints& points, double reach) {
  std::vector<uint8_t> mask(points.points.size(), 0);
  tbb::parallel_for(tbb::blocked_range<uint32_t>(0, part.num_triangles(), 64), [&](auto range) {
    for (uint32_t t = range.begin(); t != range.end(); ++t) {
      const TriangleFrame f(part, t);
      if (!f.ok) continue;
      for (uint32_t i = points.begin(t); i < points.end(t); ++i) {
        const Eigen::Vector2d p = f.Project(em.closest_point[points.points[i]]);
        for (int k = 0; k < 3; ++k) mask[i] |= (f.Outside(p, k) >= -reach) << k;
      }
    }
  });
  return mask;
}

// One triangle's sampling: a square grid of cells in its plane, the cells
// whose centres lie inside it standing for equal parts of its area. The
// grid has a margin of `reach` around the triangle, where the points of its
// neighbours land. A sample is covered when a point lies within reach of
// its centre: the points are listed per cell, and each sample looks at the
// cells around it. A cell whose every point is within reach (the "sure"
// stencil) decides by being occupied; a cell only partly within reach (the
// "maybe" stencil) by its points' distances. Inside an occupied area the
// first look decides, so the exact work is at the edges of what was seen.
class TriangleRaster {
 public:
  TriangleRaster(const TriangleMesh& part, uint32_t t, double cell_mm, double reach)
      : f_(part, t), reach_(reach) {
    if (!f_.ok) {  // degenerate: one sample, never covered, weighing nothing
      head_.assign(1, -1);
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
    head_.assign(static_cast<std::size_t>(nx_) * ny_, -1);
    inv_h_ = 1 / h_;
    const Eigen::Vector3d g = f_.At((f_.corner[1] + f_.corner[2]) / 3);
    centre_ = g.cast<float>();
    double r = 0;
    for (const auto& c : f_.corner) r = std::max(r, (f_.At(c) - g).norm());
    r += (reach_cells_ + 2) * h_;
    bound2_ = static_cast<float>(r * r);
    MakeStencils();
  }

  // Adds q when it lies on the grid within reach of the triangle (first
  // tested by the grid's bounding sphere, a cheap test). `own`: q is a
  // closest point on this triangle, so on the grid.
  void Add(const Eigen::Vector3f& q, bool own) {
    if (!own && (q - centre_).squaredNorm() > bound2_) return;
    const Eigen::Vector2d p = f_.Project(q);
    if (!own)
      for (int k = 0; k < 3; ++k)
        if (f_.Outside(p, k) > reach_) return;
    const double x = (p.x() - lo_.x()) * inv_h_, y = (p.y() - lo_.y()) * inv_h_;
    if (!(x >= 0 && y >= 0 && x < nx_ && y < ny_)) return;
    const std::size_t c = static_cast<std::size_t>(y) * nx_ + static_cast<std::size_t>(x);
    next_.push_back(head_[c]);
    points_.push_back(p);
    head_[c] = static_cast<int32_t>(points_.size() - 1);
  }

  // Calls f(3D location, covered) for each sample, after every point was
  // added.
  template <typename F>
  void ForEachSample(F&& f) const {
    for (std::size_t c : cells_)
      f(f_.At(Centre(static_cast<int>(c % nx_), static_cast<int>(c / nx_))), Covered(c));
  }
  std::size_t CountCovered() const {
    std::size_t n = 0;
    for (std::size_t c : cells_) n += Covered(c);
    return n;
  }
  std::size_t samples() const { return cells_.size(); }
  double area() const { return f_.area; }

 private:
  // The cells whose centres lie inside: per row, those around the span the
  // edges' lines allow, each tested (the span's rounding adds or drops none).
  void ListSamples() {
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
        if (Inside(Centre(ix, iy))) cells_.push_back(Index(ix, iy));
    }
  }
  std::size_t Index(int ix, int iy) const {
    return static_cast<std::size_t>(std::clamp(iy, 0, ny_ - 1)) * nx_ + std::clamp(ix, 0, nx_ - 1);
  }
  Eigen::Vector2d Centre(int ix, int iy) const {
    return lo_ + h_ * Eigen::Vector2d(ix + 0.5, iy + 0.5);
  }
  bool Inside(const Eigen::Vector2d& p) const {
    for (int k = 0; k < 3; ++k)
      if (f_.Outside(p, k) > 0) return false;
    return true;
  }
  // Cell offsets (as index steps) by the farthest and the nearest a point
  // in that cell can be from a sample's centre. A sample lies at least
  // reach_cells_ from the grid's border, so no step leaves the grid.
  void MakeStencils() {
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
  bool Covered(std::size_t c) const {
    if (!f_.ok) return false;
    for (long s : sure_)
      if (head_[c + s] >= 0) return true;
    const Eigen::Vector2d centre = Centre(static_cast<int>(c % nx_), static_cast<int>(c / nx_));
    for (long s : maybe_)
      for (int32_t i = head_[c + s]; i >= 0; i = next_[i])
        if ((points_[i] - centre).squaredNorm() <= reach_ * reach_) return true;
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
  std::vector<int32_t> head_, next_;  // per cell its last point, per point the one before
  std::vector<Eigen::Vector2d> points_;
};

// Per-triangle results: covered fraction, and per reachable comparison
// point (indexed like plan.point_ids) the area within its radius and of it
// covered.
struct TriangleSums {
  std::vector<float> covered;
  std::vector<double> point_area, point_covered;
};

// What one triangle's sampling reads: the points by triangle, which of
// them are near which edge, and the neighbours across the edges.
struct CoverageInputs {
  const std::vector<Eigen::Vector3f>& closest;  // the error map's
  const TrianglePoints& points;
  const std::vector<uint8_t>& near_edges;
  const Neighbours& neighbours;
};

// Triangle t sampled and covered by the points on it and those on the
// triangles across its edges near the shared edge (so coverage runs across
// an edge as on the surface).
void SampleTriangle(const TriangleMesh& part, const ResolvedInspectionPlan& rp,
                    const CoverageInputs& in, const CoverageSettings& s, uint32_t t,
                    TriangleSums& out) {
  // A comparison point's disc gets samples however small it is: its
  // triangles are sampled at a third of the smallest radius reaching them.
  double cell = s.sample_mm;
  for (uint32_t k = rp.point_offsets[t]; k < rp.point_offsets[t + 1]; ++k)
    cell = std::min(cell, rp.plan.points[rp.point_ids[k]].radius_mm / 3);
  TriangleRaster raster(part, t, cell, s.distance_mm);
  for (uint32_t i = in.points.begin(t); i < in.points.end(t); ++i)
    raster.Add(in.closest[in.points.points[i]], true);
  for (uint32_t k = in.neighbours.offsets[t]; k < in.neighbours.offsets[t + 1]; ++k) {
    const Neighbour& n = in.neighbours.items[k];
    for (uint32_t i = in.points.begin(n.triangle); i < in.points.end(n.triangle); ++i)
      if (in.near_edges[i] >> n.edge & 1) raster.Add(in.closest[in.points.points[i]], false);
  }
  const uint32_t first = rp.point_offsets[t], last = rp.point_offsets[t + 1];
  const std::size_t samples = raster.samples();
  if (first == last) {  // no comparison point: the count alone
    out.covered[t] = static_cast<float>(static_cast<double>(raster.CountCovered()) /
                                        static_cast<double>(samples));
    return;
  }
  std::size_t covered = 0;
  std::vector<std::pair<std::size_t, bool>> near;  // (row k, covered) per sample in a point's disc
  raster.ForEachSample([&](const Eigen::Vector3d& q, bool hit) {
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
                                               const std::atomic<bool>* cancel,
                                               const TrianglePoints* by_triangle) {
  CoverageSettings s = settings;
  if (!(s.distance_mm > 0) || !std::isfinite(s.distance_mm) || !(s.sample_mm >= 0))
    return absl::InvalidArgumentError("coverage: distance_mm must be > 0, sample_mm >= 0");
  if (s.sample_mm == 0) s.sample_mm = s.distance_mm / 2;
  if (rp.num_triangles != part.num_triangles() ||
      em.closest_point.size() != em.triangle_id.size() ||
      (by_triangle && by_triangle->offsets.size() != part.num_triangles() + 1))
    return absl::InvalidArgumentError("coverage: the plan, the part and the error map differ");
  TriangleSums sums{std::vector<float>(part.num_triangles(), 0.f),
                    std::vector<double>(rp.point_ids.size(), 0),
                    std::vector<double>(rp.point_ids.size(), 0)};
  tbb::task_arena arena(s.threads > 0 ? s.threads : tbb::task_arena::automatic);
  absl::Status status;
  arena.execute([&] {
    absl::StatusOr<TrianglePoints> own;
    if (!by_triangle) {
      own = PointsByTriangle(em, part.num_triangles());
      if (!own.ok()) return void(status = own.status());
    }
    const TrianglePoints& points = by_triangle ? *by_triangle : *own;
    const std::vector<uint8_t> near_edges = NearEdges(part, em, points, s.distance_mm);
    const Neighbours neighbours = EdgeNeighbours(part);
    const CoverageInputs in{em.closest_point, points, near_edges, neighbours};
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, rp.num_triangles, 64), [&](auto range) {
      if (IsCancelled(cancel)) return;
      for (uint32_t t = range.begin(); t != range.end(); ++t)
        SampleTriangle(part, rp, in, s, t, sums);
    });
  });
  if (!status.ok()) return absl::InvalidArgumentError(absl::StrCat("coverage: ", status.message()));
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
