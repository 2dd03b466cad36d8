#include "core/plan/section.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <unordered_map>
#include <utility>

namespace surfinspect {
namespace {

// Where a segment ends: the mesh edge it crosses, or the mesh vertex it
// passes through (the same key for every triangle around that vertex).
using EndKey = std::pair<uint32_t, uint32_t>;

struct Segment {
  Eigen::Vector3d end[2];
  EndKey key[2];
};

// The plane's crossing of triangle t, if any. A vertex on the plane counts
// as above it (s >= 0), so that a neighbouring triangle sees the same
// crossing and no segment is counted twice.
bool CutTriangle(const TriangleMesh& part, uint32_t t, const SectionPlane& plane, Segment& out) {
  const auto& tri = part.triangles[t];
  Eigen::Vector3d v[3];
  double s[3];
  for (int k = 0; k < 3; ++k) {
    v[k] = part.vertices[tri[k]].cast<double>();
    s[k] = (v[k] - plane.point_mm).dot(plane.normal);
  }
  int found = 0;
  for (int k = 0; k < 3 && found < 2; ++k) {
    const int j = (k + 1) % 3;
    if ((s[k] >= 0) == (s[j] >= 0)) continue;
    // From the lower vertex id, so that both triangles of an edge compute
    // the same bits for its crossing.
    const int lo = tri[k] < tri[j] ? k : j, hi = lo == k ? j : k;
    out.end[found] = s[lo] == 0 ? v[lo]
                     : s[hi] == 0
                         ? v[hi]
                         : Eigen::Vector3d(v[lo] + s[lo] / (s[lo] - s[hi]) * (v[hi] - v[lo]));
    out.key[found] = s[lo] == 0   ? EndKey{tri[lo], tri[lo]}
                     : s[hi] == 0 ? EndKey{tri[hi], tri[hi]}
                                  : EndKey{tri[lo], tri[hi]};
    ++found;
  }
  return found == 2;
}

// Segments chained through their shared ends into polylines; an open chain
// starts at an end no other segment shares.
std::vector<std::vector<Eigen::Vector3d>> Chain(const std::vector<Segment>& segments) {
  std::map<EndKey, std::vector<std::pair<std::size_t, int>>> at;  // key -> (segment, end)
  for (std::size_t i = 0; i < segments.size(); ++i)
    for (int e = 0; e < 2; ++e) at[segments[i].key[e]].emplace_back(i, e);
  std::vector<char> used(segments.size(), 0);
  std::vector<std::vector<Eigen::Vector3d>> out;
  const auto walk = [&](std::size_t first, int from) {
    std::vector<Eigen::Vector3d> line{segments[first].end[from]};
    std::size_t i = first;
    int e = from;
    while (true) {
      used[i] = 1;
      const int other = 1 - e;
      line.push_back(segments[i].end[other]);
      bool next = false;
      for (const auto& [j, ej] : at[segments[i].key[other]])
        if (!used[j]) {
          i = j, e = ej, next = true;
          break;
        }
      if (!next) break;
    }
    out.push_back(std::move(line));
  };
  for (std::size_t i = 0; i < segments.size(); ++i)  // open chains first
    for (int e = 0; e < 2 && !used[i]; ++e)
      if (at[segments[i].key[e]].size() == 1) walk(i, e);
  for (std::size_t i = 0; i < segments.size(); ++i)  // then closed loops
    if (!used[i]) walk(i, 0);
  return out;
}

// Whether triangle t may hold closest points within the slab: its
// vertices' offsets from the plane span the slab (widened by 1e-3 mm for
// float rounding; each point is then tested exactly).
bool NearSlab(const TriangleMesh& part, uint32_t t, const SectionPlane& plane) {
  double lo = INFINITY, hi = -INFINITY;
  for (uint32_t v : part.triangles[t]) {
    const double s = (part.vertices[v].cast<double>() - plane.point_mm).dot(plane.normal);
    lo = std::min(lo, s), hi = std::max(hi, s);
  }
  const double half = plane.width_mm / 2 + 1e-3;
  return hi >= -half && lo <= half;
}

// The error-map indices of the matched points in the slab, ascending: from
// the triangles near the slab when the points are grouped by triangle, else
// by a pass over the map.
std::vector<uint32_t> SlabPoints(const TriangleMesh& part, const ErrorMapResult& em,
                                 const SectionPlane& plane, const std::vector<uint8_t>& triangles,
                                 const TrianglePoints* by_triangle) {
  std::vector<uint32_t> out;
  const auto in_slab = [&](std::size_t i) {
    const double off = (em.closest_point[i].cast<double>() - plane.point_mm).dot(plane.normal);
    return std::abs(off) <= plane.width_mm / 2;
  };
  const auto selected = [&](uint32_t t) { return triangles.empty() || triangles[t]; };
  if (!by_triangle) {
    for (std::size_t i = 0; i < em.triangle_id.size(); ++i) {
      const uint32_t t = em.triangle_id[i];
      if (t != UINT32_MAX && selected(t) && in_slab(i)) out.push_back(static_cast<uint32_t>(i));
    }
    return out;
  }
  for (uint32_t t = 0; t < part.num_triangles(); ++t)
    if (selected(t) && NearSlab(part, t, plane))
      for (uint32_t k = by_triangle->begin(t); k < by_triangle->end(t); ++k) {
        // Runs of scan rows far apart: fetched ahead, the loads overlap.
        if (k + 16 < by_triangle->end(t))
          __builtin_prefetch(&em.closest_point[by_triangle->points[k + 16]]);
        if (in_slab(by_triangle->points[k])) out.push_back(by_triangle->points[k]);
      }
  std::sort(out.begin(), out.end());
  return out;
}

// The measured side: points in the slab, their statistics and whiskers.
void MeasuredSide(const TriangleMesh& part, const ErrorMapResult& em, const SectionPlane& plane,
                  const std::vector<uint8_t>& triangles, std::size_t max_whiskers,
                  const TrianglePoints* by_triangle, SectionCut& cut) {
  cut.points = SlabPoints(part, em, plane, triangles, by_triangle);
  double sum = 0, lo = INFINITY, hi = -INFINITY;
  for (uint32_t i : cut.points) {
    const double d = em.deviation_mm[i];
    sum += d, lo = std::min(lo, d), hi = std::max(hi, d);
  }
  if (cut.points.empty()) return;
  cut.min_mm = lo, cut.max_mm = hi;
  cut.mean_mm = sum / static_cast<double>(cut.points.size());
  const std::vector<Eigen::Vector3f> normals = part.FaceNormals();
  const std::size_t step = std::max<std::size_t>(
      1, (cut.points.size() + max_whiskers - 1) / std::max<std::size_t>(max_whiskers, 1));
  for (std::size_t k = 0; k < cut.points.size() && max_whiskers > 0; k += step) {
    const uint32_t i = cut.points[k];
    const Eigen::Vector3d n = normals[em.triangle_id[i]].cast<double>();
    const Eigen::Vector3d in_plane = n - n.dot(plane.normal) * plane.normal;
    if (!(in_plane.norm() > 1e-6)) continue;  // a face parallel to the plane has no curve normal
    cut.whiskers.push_back(
        {em.closest_point[i].cast<double>(), in_plane.normalized(), em.deviation_mm[i]});
  }
}

// The slab's closest points hashed by cells of `cell` mm, for the curve's
// samples to find their neighbours among.
class PointCells {
 public:
  PointCells(const SectionCut& cut, const ErrorMapResult& em, double cell) : em_(em), cell_(cell) {
    for (uint32_t i : cut.points)
      cells_[Key(Cell(em.closest_point[i].cast<double>()))].push_back(i);
  }
  // Whether a point lies within `cell` of q (in q's cell or one around it).
  bool Near(const Eigen::Vector3d& q) const {
    const Eigen::Vector3i c = Cell(q);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find(Key(c + Eigen::Vector3i(dx, dy, dz)));
          if (it == cells_.end()) continue;
          for (uint32_t i : it->second)
            if ((em_.closest_point[i].cast<double>() - q).squaredNorm() <= cell_ * cell_)
              return true;
        }
    return false;
  }

 private:
  Eigen::Vector3i Cell(const Eigen::Vector3d& p) const {
    return (p / cell_).array().floor().max(-1e6).min(1e6).cast<int>();
  }
  static uint64_t Key(const Eigen::Vector3i& c) {
    const auto u = [](int v) { return static_cast<uint64_t>(v + (1 << 20)) & 0x1fffff; };
    return u(c.x()) << 42 | u(c.y()) << 21 | u(c.z());
  }
  const ErrorMapResult& em_;
  double cell_;
  std::unordered_map<uint64_t, std::vector<uint32_t>> cells_;
};

}  // namespace

double SectionCoverage(const SectionCut& cut, const ErrorMapResult& em, double distance_mm) {
  const PointCells cells(cut, em, distance_mm);
  double total = 0, seen = 0;
  for (const auto& line : cut.polylines)
    for (std::size_t k = 0; k + 1 < line.size(); ++k) {
      const Eigen::Vector3d a = line[k], b = line[k + 1];
      const double length = (b - a).norm();
      const int n = std::max(1, static_cast<int>(std::ceil(length / (distance_mm / 2))));
      for (int j = 0; j < n; ++j) {
        total += length / n;
        if (cells.Near(a + (j + 0.5) / n * (b - a))) seen += length / n;
      }
    }
  return total > 0 ? seen / total : 0;
}

absl::StatusOr<SectionCut> CutSection(const TriangleMesh& part, const ErrorMapResult& em,
                                      const SectionPlane& given,
                                      const std::vector<uint8_t>& triangles,
                                      std::size_t max_whiskers, const TrianglePoints* by_triangle) {
  if (!given.normal.allFinite() || !(given.normal.norm() > 0) || !given.point_mm.allFinite())
    return absl::InvalidArgumentError("section: the plane needs a point and a non-zero normal");
  if (!(given.width_mm > 0) || !std::isfinite(given.width_mm))
    return absl::InvalidArgumentError("section: width_mm must be > 0");
  if (!triangles.empty() && triangles.size() != part.num_triangles())
    return absl::InvalidArgumentError("section: the triangle selection is not the part's");
  if (em.closest_point.size() != em.triangle_id.size() ||
      em.deviation_mm.size() != em.triangle_id.size())
    return absl::InvalidArgumentError("section: error map arrays differ in size");
  if (by_triangle && by_triangle->offsets.size() != part.num_triangles() + 1)
    return absl::InvalidArgumentError("section: the points by triangle are not the part's");
  if (!by_triangle)  // grouping the points checked their ids
    for (uint32_t t : em.triangle_id)
      if (t != UINT32_MAX && t >= part.num_triangles())
        return absl::InvalidArgumentError("section: triangle id beyond the part mesh");
  SectionPlane plane = given;
  plane.normal.normalize();
  std::vector<Segment> segments;
  Segment s;
  for (uint32_t t = 0; t < part.num_triangles(); ++t)
    if ((triangles.empty() || triangles[t]) && CutTriangle(part, t, plane, s))
      segments.push_back(s);
  SectionCut cut;
  cut.plane = plane;
  cut.segments = segments.size();
  cut.polylines = Chain(segments);
  MeasuredSide(part, em, plane, triangles, max_whiskers, by_triangle, cut);
  return cut;
}

}  // namespace surfinspect
