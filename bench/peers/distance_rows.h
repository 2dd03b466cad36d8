// Closest-point distances against Open3D 0.16's
// RaycastingScene::ComputeDistance on the same points and mesh: a torus
// (R = 100 mm, r = 30 mm) tessellated into ~150k triangles, 10^6 points
// within +-0.5 mm of it, once in scan order (a 1000x1000 (u, v) raster,
// passed as an organized cloud) and once shuffled. Both sides use every core
// and have their BVH built before timing (Open3D commits its scene on the
// first query: one untimed warm-up). Agreement: the largest |difference| of
// the unsigned distances. Plus the scaling rows: 10^5..10^7 points on that
// mesh, and 10^3..10^6 triangles for 10^5 points (build and query).
#pragma once

#include <cmath>
#include <random>
#include <tuple>

#include "bench/peers/report.h"
#include "core/distance/mesh_index.h"
#ifdef SURFINSPECT_HAVE_OPEN3D
#include <open3d/core/Tensor.h>
#include <open3d/t/geometry/RaycastingScene.h>
#endif

namespace surfinspect::bench {

namespace distance_detail {

constexpr double kR = 100.0, kr = 30.0;  // torus radii, mm

inline Eigen::Vector3d TorusPoint(double u, double v, double offset_mm) {
  const Eigen::Vector3d n(std::cos(v) * std::cos(u), std::cos(v) * std::sin(u), std::sin(v));
  const Eigen::Vector3d centre(kR * std::cos(u), kR * std::sin(u), 0);
  return centre + (kr + offset_mm) * n;
}

// nu x nv quads, 2 triangles each, outward CCW normals.
inline TriangleMesh Torus(uint32_t nu, uint32_t nv) {
  TriangleMesh m;
  for (uint32_t i = 0; i < nu; ++i)
    for (uint32_t j = 0; j < nv; ++j)
      m.vertices.push_back(TorusPoint(2 * M_PI * i / nu, 2 * M_PI * j / nv, 0).cast<float>());
  auto id = [&](uint32_t i, uint32_t j) { return (i % nu) * nv + (j % nv); };
  for (uint32_t i = 0; i < nu; ++i)
    for (uint32_t j = 0; j < nv; ++j) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

// side x side raster in (u, v), each point moved along the normal by a
// uniform offset in [-0.5, 0.5] mm: scan order.
inline PointCloud RasterPoints(uint32_t side, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> off(-0.5, 0.5);
  PointCloud c = PointCloud::Organized(side, side);
  for (uint32_t r = 0; r < side; ++r)
    for (uint32_t k = 0; k < side; ++k)
      c.points[std::size_t(r) * side + k] =
          TorusPoint(2 * M_PI * (k + 0.5) / side, 2 * M_PI * (r + 0.5) / side, off(rng))
              .cast<float>();
  return c;
}

inline PointCloud RandomPoints(std::size_t n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> off(-0.5, 0.5), ang(0, 2 * M_PI);
  std::vector<Eigen::Vector3f> pts(n);
  for (auto& p : pts) {
    const double u = ang(rng), v = ang(rng);
    p = TorusPoint(u, v, off(rng)).cast<float>();
  }
  return PointCloud::Unorganized(std::move(pts));
}

inline void OurDistances(const MeshIndex& index, const PointCloud& pts, std::vector<float>& out) {
  out.assign(pts.size(), NAN);
  (void)QueryClosestEach(
      index, pts, Eigen::Isometry3d::Identity(), {}, nullptr,
      [&](std::size_t i, const ClosestPoint& c) { out[i] = float(c.distance_mm); });
}

#ifdef SURFINSPECT_HAVE_OPEN3D
namespace o3c = open3d::core;
struct Open3dScene {
  open3d::t::geometry::RaycastingScene scene;
  explicit Open3dScene(const TriangleMesh& m) {
    std::vector<float> v;
    for (const auto& p : m.vertices) v.insert(v.end(), {p.x(), p.y(), p.z()});
    std::vector<uint32_t> t;
    for (const auto& tri : m.triangles) t.insert(t.end(), {tri[0], tri[1], tri[2]});
    scene.AddTriangles(o3c::Tensor(v, {int64_t(m.vertices.size()), 3}, o3c::Float32),
                       o3c::Tensor(t, {int64_t(m.triangles.size()), 3}, o3c::UInt32));
  }
  static o3c::Tensor Points(const PointCloud& c) {
    return o3c::Tensor(c.points[0].data(), {int64_t(c.size()), 3}, o3c::Float32);
  }
  void Distances(const o3c::Tensor& q, std::vector<float>& out) {
    const o3c::Tensor d = scene.ComputeDistance(q, 0);
    out = d.ToFlatVector<float>();
  }
};
#endif

inline double MaxAbsDiff(const std::vector<float>& a, const std::vector<float>& b) {
  double m = 0;
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i)
    m = std::max(m, std::abs(double(a[i]) - double(b[i])));
  return m;
}

const char* const kNoOpen3d = "skipped (libopen3d-dev not installed)";

}  // namespace distance_detail

inline void AddDistanceRows(std::vector<Row>& rows, std::vector<ScalingRow>& scaling) {
  using namespace distance_detail;
  const TriangleMesh mesh = Torus(500, 150);  // 150,000 triangles
  auto index = MeshIndex::Build(mesh);
  if (!index.ok()) {
    rows.push_back({"Closest-point distances", "failed: " + std::string(index.status().message()),
                    "", "", "", "", ""});
    return;
  }
  const PointCloud scan_order = RasterPoints(1000, 7);
  std::vector<std::size_t> perm(scan_order.size());
  for (std::size_t i = 0; i < perm.size(); ++i) perm[i] = i;
  std::shuffle(perm.begin(), perm.end(), std::mt19937_64(3));
  std::vector<Eigen::Vector3f> shuffled(perm.size());
  for (std::size_t i = 0; i < perm.size(); ++i) shuffled[i] = scan_order.points[perm[i]];
  const PointCloud random_order = PointCloud::Unorganized(std::move(shuffled));

#ifdef SURFINSPECT_HAVE_OPEN3D
  Open3dScene o3d(mesh);
  std::vector<float> warm;
  o3d.Distances(Open3dScene::Points(RandomPoints(1000, 1)), warm);  // commits the BVH
#endif
  for (const auto* which : {&random_order, &scan_order}) {
    const bool scan = which == &scan_order;
    std::vector<float> ours, peer;
    double t_ours = 0;
#ifdef SURFINSPECT_HAVE_OPEN3D
    const o3c::Tensor q = Open3dScene::Points(*which);
    double t_peer = 0;
    std::tie(t_ours, t_peer) = MedianSecondsInterleaved(
        3, true, [&] { OurDistances(**index, *which, ours); }, [&] { o3d.Distances(q, peer); });
#else
    t_ours = MedianSeconds(3, true, [&] { OurDistances(**index, *which, ours); });
#endif
    Row row{std::string("Closest-point distances, 10^6 near-surface points, 150k triangles, ") +
                (scan ? "scan order" : "random order") + " (2 threads)",
            Time(t_ours) + Fmt(" (%.2f M pts/s)", 1e-6 * which->size() / t_ours),
            kNoOpen3d,
            "—",
            "—",
            "≥ 5x Open3D throughput",
            "—"};
#ifdef SURFINSPECT_HAVE_OPEN3D
    row.peer = Time(t_peer) + " (Open3D ComputeDistance)";
    row.ratio = Fmt("%.1fx", t_peer / t_ours);
    row.agreement = Fmt("max abs(ours − Open3D) = %.2g mm", MaxAbsDiff(ours, peer));
    row.met = Verdict(t_peer / t_ours >= 5);
#endif
    rows.push_back(row);
  }

  // Scaling in points: random order on the same mesh.
  for (std::size_t n : {std::size_t(100'000), std::size_t(1'000'000), std::size_t(10'000'000)}) {
    const PointCloud pts = RandomPoints(n, 11);
    const int reps = n >= 10'000'000 ? 1 : 3;
    std::vector<float> ours, peer;
    double t_ours = 0;
#ifdef SURFINSPECT_HAVE_OPEN3D
    const o3c::Tensor q = Open3dScene::Points(pts);
    double t_peer = 0;
    std::tie(t_ours, t_peer) = MedianSecondsInterleaved(
        reps, false, [&] { OurDistances(**index, pts, ours); }, [&] { o3d.Distances(q, peer); });
#else
    t_ours = MedianSeconds(reps, false, [&] { OurDistances(**index, pts, ours); });
#endif
    ScalingRow row{
        Fmt("distances, 10^%.0f points (random order), 150k triangles", std::log10(double(n))),
        Time(t_ours) + Fmt(" (%.0f ns/pt)", 1e9 * t_ours / n), kNoOpen3d, ""};
#ifdef SURFINSPECT_HAVE_OPEN3D
    row.peer = Time(t_peer) + Fmt(" (%.0f ns/pt)", 1e9 * t_peer / n);
    row.note = Fmt("Open3D / ours %.1fx", t_peer / t_ours) +
               Fmt(", max diff %.2g mm", MaxAbsDiff(ours, peer));
#endif
    if (reps == 1) row.note += (row.note.empty() ? "" : "; ") + std::string("measured once");
    scaling.push_back(row);
  }

  // Scaling in triangles: 10^5 random points; BVH build + queries.
  const std::pair<uint32_t, uint32_t> grids[] = {{50, 10}, {100, 50}, {500, 100}, {1000, 500}};
  for (const auto& [nu, nv] : grids) {
    const TriangleMesh m = Torus(nu, nv);
    const PointCloud pts = RandomPoints(100'000, 13);
    std::vector<float> ours, peer;
    double build = 0;
    const double t_query = [&] {
      auto idx = MeshIndex::Build(m);
      if (!idx.ok()) return double(NAN);
      build = (*idx)->info().build_seconds;
      return MedianSeconds(3, true, [&] { OurDistances(**idx, pts, ours); });
    }();
    ScalingRow row{Fmt("distances, 10^5 points, %.0f triangles (BVH build, then query)",
                       double(m.num_triangles())),
                   "build " + Time(build) + ", query " + Time(t_query), kNoOpen3d, ""};
#ifdef SURFINSPECT_HAVE_OPEN3D
    double t_build_peer = 0, t_peer = 0;
    {
      const auto t0 = std::chrono::steady_clock::now();
      Open3dScene s(m);
      std::vector<float> w;
      s.Distances(Open3dScene::Points(RandomPoints(1, 1)), w);  // commit = BVH build
      t_build_peer = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const o3c::Tensor q = Open3dScene::Points(pts);
      t_peer = MedianSeconds(3, false, [&] { s.Distances(q, peer); });
    }
    row.peer = "build " + Time(t_build_peer) + ", query " + Time(t_peer);
    row.note = Fmt("query Open3D / ours %.1fx", t_peer / t_query) +
               Fmt(", max diff %.2g mm", MaxAbsDiff(ours, peer));
#endif
    scaling.push_back(row);
  }
}

}  // namespace surfinspect::bench
