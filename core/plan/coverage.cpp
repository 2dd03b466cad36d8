#include "core/plan/coverage.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "absl/container/flat_hash_map.h"

namespace surfinspect {
namespace {

constexpr int kMaxSubdivisions = 2000;  // a 1 m triangle at 0.5 mm: 4 M samples

// The matched closest points in cells `cell_mm` wide.
class PointGrid {
 public:
  PointGrid(const ErrorMapResult& em, double cell_mm) : inv_(1.0 / cell_mm) {
    std::vector<std::pair<uint64_t, Eigen::Vector3f>> keyed;
    for (std::size_t i = 0; i < em.triangle_id.size(); ++i)
      if (em.triangle_id[i] != UINT32_MAX)
        keyed.emplace_back(Key(Cell(em.closest_point[i].cast<double>())), em.closest_point[i]);
    std::sort(keyed.begin(), keyed.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    points_.reserve(keyed.size());
    for (std::size_t k = 0; k < keyed.size(); ++k) {
      if (k == 0 || keyed[k].first != keyed[k - 1].first)
        ranges_[keyed[k].first] = {static_cast<uint32_t>(k), static_cast<uint32_t>(k)};
      ranges_[keyed[k].first].second = static_cast<uint32_t>(k + 1);
      points_.push_back(keyed[k].second);
    }
  }

  // Whether a point lies within `reach` (<= the cell size) of q. The own
  // cell first: on a covered surface it nearly always answers.
  bool AnyWithin(const Eigen::Vector3d& q, double reach) const {
    const Eigen::Vector3i c = Cell(q);
    const Eigen::Vector3f qf = q.cast<float>();
    const auto r2 = static_cast<float>(reach * reach);
    if (InCell(Key(c), qf, r2)) return true;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          if ((dx | dy | dz) != 0 && InCell(Key(c + Eigen::Vector3i(dx, dy, dz)), qf, r2))
            return true;
    return false;
  }

 private:
  bool InCell(uint64_t key, const Eigen::Vector3f& q, float r2) const {
    const auto it = ranges_.find(key);
    if (it == ranges_.end()) return false;
    for (uint32_t k = it->second.first; k < it->second.second; ++k)
      if ((points_[k] - q).squaredNorm() <= r2) return true;
    return false;
  }
  Eigen::Vector3i Cell(const Eigen::Vector3d& p) const {
    return (p * inv_).array().floor().cast<int>();
  }
  static uint64_t Key(const Eigen::Vector3i& c) {
    const auto u = [](int v) { return static_cast<uint64_t>(static_cast<uint32_t>(v) & 0x1fffff); };
    return u(c.x()) | u(c.y()) << 21 | u(c.z()) << 42;
  }

  double inv_;
  absl::flat_hash_map<uint64_t, std::pair<uint32_t, uint32_t>> ranges_;
  std::vector<Eigen::Vector3f> points_;
};

// Calls f(centroid) for the n x n congruent sub-triangles of (a, b, c).
template <typename F>
void ForEachSubTriangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                        const Eigen::Vector3d& c, int n, F&& f) {
  const Eigen::Vector3d e1 = (b - a) / n, e2 = (c - a) / n;
  for (int i = 0; i < n; ++i)
    for (int j = 0; i + j < n; ++j) {
      f(a + (i + 1.0 / 3) * e1 + (j + 1.0 / 3) * e2);                     // "up"
      if (i + j + 1 < n) f(a + (i + 2.0 / 3) * e1 + (j + 2.0 / 3) * e2);  // "down"
    }
}

// Per-triangle sums: covered fraction, and per reachable comparison point
// (indexed like plan.point_ids) the area within its radius and of it covered.
struct TriangleSums {
  std::vector<float> covered;
  std::vector<double> point_area, point_covered;
};

void SampleTriangle(const TriangleMesh& part, const ResolvedInspectionPlan& rp,
                    const PointGrid& grid, const CoverageSettings& s, uint32_t t,
                    TriangleSums& out) {
  const auto& tri = part.triangles[t];
  const Eigen::Vector3d a = part.vertices[tri[0]].cast<double>(),
                        b = part.vertices[tri[1]].cast<double>(),
                        c = part.vertices[tri[2]].cast<double>();
  const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
  const int n = std::clamp(static_cast<int>(std::ceil(longest / s.sample_mm)), 1, kMaxSubdivisions);
  const double sub_area = 0.5 * (b - a).cross(c - a).norm() / (double(n) * n);
  const uint32_t first = rp.point_offsets[t], last = rp.point_offsets[t + 1];
  std::size_t covered = 0;
  ForEachSubTriangle(a, b, c, n, [&](const Eigen::Vector3d& q) {
    const bool hit = grid.AnyWithin(q, s.distance_mm);
    covered += hit;
    for (uint32_t k = first; k < last; ++k) {
      const ComparisonPoint& p = rp.plan.points[rp.point_ids[k]];
      if ((q - p.position_mm).squaredNorm() > p.radius_mm * p.radius_mm) continue;
      out.point_area[k] += sub_area;
      out.point_covered[k] += hit ? sub_area : 0;
    }
  });
  out.covered[t] = static_cast<float>(static_cast<double>(covered) / (double(n) * n));
}

double Fraction(double covered, double area) { return area > 0 ? covered / area : 0; }

}  // namespace

absl::StatusOr<CoverageResult> ComputeCoverage(const ErrorMapResult& em, const TriangleMesh& part,
                                               const ResolvedInspectionPlan& rp,
                                               const CoverageSettings& settings) {
  CoverageSettings s = settings;
  if (!(s.distance_mm > 0) || !std::isfinite(s.distance_mm) || !(s.sample_mm >= 0))
    return absl::InvalidArgumentError("coverage: distance_mm must be > 0, sample_mm >= 0");
  if (s.sample_mm == 0) s.sample_mm = s.distance_mm / 2;
  if (rp.num_triangles != part.num_triangles() || em.closest_point.size() != em.triangle_id.size())
    return absl::InvalidArgumentError("coverage: the plan, the part and the error map differ");
  const PointGrid grid(em, s.distance_mm);
  TriangleSums sums{std::vector<float>(part.num_triangles(), 0.f),
                    std::vector<double>(rp.point_ids.size(), 0),
                    std::vector<double>(rp.point_ids.size(), 0)};
  tbb::task_arena arena(s.threads > 0 ? s.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, rp.num_triangles, 64), [&](auto range) {
      for (uint32_t t = range.begin(); t != range.end(); ++t)
        SampleTriangle(part, rp, grid, s, t, sums);
    });
  });
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
