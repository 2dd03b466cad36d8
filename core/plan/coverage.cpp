#include "core/plan/coverage.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "absl/strings/str_cat.h"
#include "core/plan/triangle_raster.h"
#include "core/types/cancel.h"

namespace surfinspect {
namespace {

constexpr uint32_t kAhead = 16;  // points fetched ahead of use

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

// Per wanted triangle t and edge k, the closest points on t that lie within
// `reach` of edge k's line, in t's plane: band(t, k). Only these can cover
// the neighbour across edge k: on a flat or gently bent surface the
// neighbour lies beyond that line; across a sharp fold a point deep in its
// face no longer reaches the other face's edge by projection. Listed
// contiguously so that a neighbour reads just them.
class EdgeBands {
 public:
  EdgeBands(const TriangleMesh& part, const ErrorMapResult& em, const TrianglePoints& points,
            double reach, const std::vector<uint8_t>& wanted) {
    const uint32_t triangles = static_cast<uint32_t>(part.num_triangles());
    std::vector<uint8_t> mask(points.points.size(), 0);
    offsets_.assign(3 * std::size_t{triangles} + 1, 0);
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, triangles, 64), [&](auto range) {
      for (uint32_t t = range.begin(); t != range.end(); ++t) {
        const TriangleFrame f(part, t);
        if (!f.ok || !wanted[t]) continue;
        for (uint32_t i = points.begin(t); i < points.end(t); ++i) {
          if (i + kAhead < points.end(t))
            __builtin_prefetch(&em.closest_point[points.points[i + kAhead]]);
          const Eigen::Vector2d p = f.Project(em.closest_point[points.points[i]]);
          for (int k = 0; k < 3; ++k) {
            const bool near = f.Outside(p, k) >= -reach;
            mask[i] |= near << k;
            offsets_[3 * t + k + 1] += near;
          }
        }
      }
    });
    for (std::size_t j = 1; j < offsets_.size(); ++j) offsets_[j] += offsets_[j - 1];
    q_.resize(offsets_.back());
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, triangles, 64), [&](auto range) {
      for (uint32_t t = range.begin(); t != range.end(); ++t) {
        if (!wanted[t]) continue;
        uint32_t at[3] = {offsets_[3 * t], offsets_[3 * t + 1], offsets_[3 * t + 2]};
        for (uint32_t i = points.begin(t); i < points.end(t); ++i)
          for (int k = 0; k < 3; ++k)
            if (mask[i] >> k & 1) q_[at[k]++] = em.closest_point[points.points[i]];
      }
    });
  }
  const Eigen::Vector3f* begin(uint32_t t, int k) const { return q_.data() + offsets_[3 * t + k]; }
  const Eigen::Vector3f* end(uint32_t t, int k) const {
    return q_.data() + offsets_[3 * t + k + 1];
  }

 private:
  std::vector<uint32_t> offsets_;  // band (t, k): q_[offsets_[3t + k] .. offsets_[3t + k + 1])
  std::vector<Eigen::Vector3f> q_;
};

// Per-triangle results: covered fraction, and per reachable comparison
// point (indexed like plan.point_ids) the area within its radius and of it
// covered.
struct TriangleSums {
  std::vector<float> covered;
  std::vector<double> point_area, point_covered;
};

// What one triangle's sampling reads: the points by triangle and the
// neighbours across the edges.
struct CoverageInputs {
  const std::vector<Eigen::Vector3f>& closest;  // the error map's
  const TrianglePoints& points;
  const Neighbours& neighbours;
};

// The samples of t within a comparison point's radius, added to its area
// and covered area.
void AddPointDiscs(const ResolvedInspectionPlan& rp, uint32_t t, const TriangleRaster& raster,
                   TriangleSums& out) {
  const uint32_t first = rp.point_offsets[t], last = rp.point_offsets[t + 1];
  std::vector<std::pair<std::size_t, bool>> near;  // (row k, covered) per sample in a point's disc
  raster.ForEachSample([&](const Eigen::Vector3d& q, bool hit) {
    for (uint32_t k = first; k < last; ++k) {
      const ComparisonPoint& p = rp.plan.points[rp.point_ids[k]];
      if ((q - p.position_mm).squaredNorm() <= p.radius_mm * p.radius_mm) near.emplace_back(k, hit);
    }
  });
  const double sample_area = raster.area() / static_cast<double>(raster.samples());
  for (const auto& [k, hit] : near) {
    out.point_area[k] += sample_area;
    out.point_covered[k] += hit ? sample_area : 0;
  }
}

bool NeighboursHavePoints(const CoverageInputs& in, uint32_t t) {
  for (uint32_t k = in.neighbours.offsets[t]; k < in.neighbours.offsets[t + 1]; ++k)
    if (in.points.end(in.neighbours.items[k].triangle) >
        in.points.begin(in.neighbours.items[k].triangle))
      return true;
  return false;
}

// Triangle t's raster, covered by the points on it.
std::unique_ptr<TriangleRaster> CoverByOwn(const TriangleMesh& part,
                                           const ResolvedInspectionPlan& rp,
                                           const CoverageInputs& in, const CoverageSettings& s,
                                           uint32_t t) {
  // A comparison point's disc gets samples however small it is: its
  // triangles are sampled at a third of the smallest radius reaching them.
  double cell = s.sample_mm;
  for (uint32_t k = rp.point_offsets[t]; k < rp.point_offsets[t + 1]; ++k)
    cell = std::min(cell, rp.plan.points[rp.point_ids[k]].radius_mm / 3);
  auto raster = std::make_unique<TriangleRaster>(part, t, cell, s.distance_mm);
  raster->Cover([&](auto&& add) {
    for (uint32_t i = in.points.begin(t); i < in.points.end(t); ++i) {
      // A triangle's points lie in short runs of scan rows far apart:
      // fetched ahead, their loads overlap instead of stalling one by one.
      if (i + kAhead < in.points.end(t))
        __builtin_prefetch(&in.closest[in.points.points[i + kAhead]]);
      add(in.closest[in.points.points[i]], true);
    }
  });
  return raster;
}

// The samples of t still uncovered, covered by the points of the triangles
// across its edges near the shared edge (so coverage runs across an edge
// as on the surface).
void CoverByBands(const CoverageInputs& in, const EdgeBands& bands, uint32_t t,
                  TriangleRaster& raster) {
  raster.Cover([&](auto&& add) {
    for (uint32_t k = in.neighbours.offsets[t]; k < in.neighbours.offsets[t + 1]; ++k) {
      const Neighbour& n = in.neighbours.items[k];
      for (auto* q = bands.begin(n.triangle, n.edge); q != bands.end(n.triangle, n.edge); ++q)
        add(*q, false);
    }
  });
}

void Record(const ResolvedInspectionPlan& rp, uint32_t t, const TriangleRaster& raster,
            TriangleSums& out) {
  out.covered[t] = static_cast<float>(static_cast<double>(raster.CountCovered()) /
                                      static_cast<double>(raster.samples()));
  if (rp.point_offsets[t] < rp.point_offsets[t + 1]) AddPointDiscs(rp, t, raster, out);
}

// Every triangle sampled and covered: first by its own points (enough for
// most), then the rest by their neighbours' bands, built for them alone.
void CoverTriangles(const TriangleMesh& part, const ResolvedInspectionPlan& rp,
                    const ErrorMapResult& em, const TrianglePoints& points,
                    const CoverageSettings& s, const std::atomic<bool>* cancel,
                    TriangleSums& sums) {
  const Neighbours neighbours = EdgeNeighbours(part);
  const CoverageInputs in{em.closest_point, points, neighbours};
  std::vector<std::unique_ptr<TriangleRaster>> needy(rp.num_triangles);
  tbb::parallel_for(tbb::blocked_range<uint32_t>(0, rp.num_triangles, 64), [&](auto range) {
    if (IsCancelled(cancel)) return;
    for (uint32_t t = range.begin(); t != range.end(); ++t) {
      auto raster = CoverByOwn(part, rp, in, s, t);
      if (raster->AllCovered() || !raster->ok() || !NeighboursHavePoints(in, t))
        Record(rp, t, *raster, sums);
      else
        needy[t] = std::move(raster);
    }
  });
  std::vector<uint8_t> wanted(rp.num_triangles, 0);  // the bands the needy ones read
  for (uint32_t t = 0; t < rp.num_triangles; ++t)
    for (uint32_t k = neighbours.offsets[t]; needy[t] && k < neighbours.offsets[t + 1]; ++k)
      wanted[neighbours.items[k].triangle] = 1;
  const EdgeBands bands(part, em, points, s.distance_mm, wanted);
  tbb::parallel_for(tbb::blocked_range<uint32_t>(0, rp.num_triangles, 64), [&](auto range) {
    if (IsCancelled(cancel)) return;
    for (uint32_t t = range.begin(); t != range.end(); ++t)
      if (needy[t]) {
        CoverByBands(in, bands, t, *needy[t]);
        Record(rp, t, *needy[t], sums);
        needy[t].reset();
      }
  });
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
    CoverTriangles(part, rp, em, points, s, cancel, sums);
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
