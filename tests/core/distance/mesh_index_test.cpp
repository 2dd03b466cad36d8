// Covers core/distance/mesh_index.cpp (MeshIndex::Closest against brute force),
// core/distance/mesh_index_normals.cpp (signs against winding numbers),
// core/distance/mesh_index_build.cpp (Build, in either triangle order, with
// and without certificates) and core/distance/mesh_index_batch.cpp (QueryClosest and
// QueryClosestEach: one and many threads, coherent start, Morton order, cancel, bad input).
#include "core/distance/mesh_index.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <random>

#include "core/distance/wide_bvh.h"
#include "tests/support/test_meshes.h"

namespace surfinspect {
namespace {

using Eigen::Vector3d;
using testing::DistanceByProjection;

Vector3d V(const TriangleMesh& m, uint32_t i) { return m.vertices[i].cast<double>(); }

// Brute force over every triangle with the same kernel: the lexicographic
// minimum of (squared distance, triangle id), as the index promises.
struct Brute {
  uint32_t triangle = UINT32_MAX;
  double d2 = INFINITY;
  Vector3d point;
  double independent = INFINITY;  // min over DistanceByProjection
};
Brute BruteForce(const TriangleMesh& m, const Vector3d& p) {
  Brute b;
  for (uint32_t t = 0; t < m.num_triangles(); ++t) {
    const auto& tri = m.triangles[t];
    const auto r = ClosestPointOnTriangle(p, V(m, tri[0]), V(m, tri[1]), V(m, tri[2]));
    if (r.squared_distance < b.d2) {
      b.d2 = r.squared_distance;
      b.triangle = t;
      b.point = r.point;
    }
    b.independent =
        std::min(b.independent, DistanceByProjection(p, V(m, tri[0]), V(m, tri[1]), V(m, tri[2])));
  }
  return b;
}

// A random soup of triangles of 1-30 mm in a 100 mm box.
TriangleMesh RandomSoup(int n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> centre(0, 100), size(-15, 15);
  TriangleMesh m;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3f c(centre(rng), centre(rng), centre(rng));
    for (int k = 0; k < 3; ++k)
      m.vertices.push_back(c + Eigen::Vector3f(size(rng), size(rng), size(rng)));
    const auto b = static_cast<uint32_t>(3 * i);
    m.triangles.push_back({b, b + 1, b + 2});
  }
  return m;
}

// Far, near, on vertices, on edges and on faces of `m`.
std::vector<Vector3d> OracleQueryPoints(const TriangleMesh& m, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  const Bounds3 b = ComputeBounds(m);
  const Vector3d lo = b.min - Vector3d::Constant(20), hi = b.max + Vector3d::Constant(20);
  std::vector<Vector3d> pts;
  for (int i = 0; i < 300; ++i)
    pts.push_back(lo + (hi - lo).cwiseProduct(Vector3d(u(rng), u(rng), u(rng))));
  for (int i = 0; i < 50; ++i)
    pts.push_back(Vector3d(u(rng) - .5, u(rng) - .5, u(rng) - .5).normalized() * 1e4);
  for (int i = 0; i < 100; ++i) {
    const auto& tri = m.triangles[rng() % m.num_triangles()];
    const Vector3d a = V(m, tri[0]), bb = V(m, tri[1]), c = V(m, tri[2]);
    const double s = u(rng), t = u(rng) * (1 - s);
    pts.push_back(a);                               // on a vertex
    pts.push_back(a + u(rng) * (bb - a));           // on an edge
    pts.push_back(a + s * (bb - a) + t * (c - a));  // on the face
  }
  return pts;
}

// Every search this machine runs, with both kinds of build and with the
// hint certificates on and off: the answers must be the same in each.
std::vector<MeshIndexSettings> AllSearches() {
  std::vector<MeshIndexSettings> all;
  for (SearchIsa isa : {SearchIsa::kSse2, SearchIsa::kAvx2})
    for (BvhQuality quality : {BvhQuality::kLow, BvhQuality::kHigh})
      for (bool certificates : {true, false}) {
        if (!SearchIsaSupported(isa)) continue;
        MeshIndexSettings s;
        s.search_isa = isa;
        s.build_quality = quality;
        s.hint_certificates = certificates;
        all.push_back(s);
      }
  return all;
}

void ExpectMatchesBruteForce(const TriangleMesh& m, const std::vector<Vector3d>& pts) {
  std::vector<std::unique_ptr<MeshIndex>> indices;
  for (const MeshIndexSettings& s : AllSearches()) {
    auto index = MeshIndex::Build(m, s);
    ASSERT_TRUE(index.ok()) << index.status();
    indices.push_back(*std::move(index));
  }
  for (const Vector3d& p : pts) {
    const Brute want = BruteForce(m, p);
    for (const auto& index : indices) {
      const ClosestPoint got = index->Closest(p);
      ASSERT_TRUE(got.matched());
      // Same kernel on the same doubles: the BVH must not change the answer.
      EXPECT_EQ(got.triangle_id, want.triangle) << p.transpose() << " " << index->info().search_isa;
      EXPECT_EQ(got.distance_mm, std::sqrt(want.d2));
      EXPECT_EQ(got.point, want.point);
      // Independent kernel: within 1e-9 relative (1e-9 mm floor on the surface).
      EXPECT_NEAR(got.distance_mm, want.independent, 1e-9 * std::max(1.0, want.independent));
      EXPECT_EQ(std::abs(got.signed_distance_mm), got.distance_mm);
      // A hint (any triangle, near or far) never changes the answer.
      for (uint32_t hint : {want.triangle, static_cast<uint32_t>(m.num_triangles() / 2), 0u}) {
        const ClosestPoint hinted = index->Closest(p, INFINITY, hint);
        EXPECT_EQ(hinted.triangle_id, got.triangle_id);
        EXPECT_EQ(hinted.distance_mm, got.distance_mm);
        EXPECT_EQ(hinted.signed_distance_mm, got.signed_distance_mm);
      }
    }
  }
}

TEST(MeshIndex, ClosestIsTheBruteForceMinimiserOnRandomSoups) {
  for (uint64_t seed : {1, 2, 3}) {
    const TriangleMesh m = RandomSoup(300, seed);
    ExpectMatchesBruteForce(m, OracleQueryPoints(m, seed + 10));
  }
}

// Triangles of 10^5 mm among ones of 10^-2 mm, so boxes and bounds span
// seven orders of magnitude.
TEST(MeshIndex, ClosestIsTheBruteForceMinimiserAmongHugeAndTinyTriangles) {
  TriangleMesh m = RandomSoup(200, 8);
  for (std::size_t i = 0; i < m.vertices.size(); ++i) {
    const float scale = i / 3 % 4 == 0 ? 5e3f : i / 3 % 4 == 1 ? 1e-3f : 1.f;
    m.vertices[i] = m.vertices[3 * (i / 3)] + scale * (m.vertices[i] - m.vertices[3 * (i / 3)]);
  }
  ExpectMatchesBruteForce(m, OracleQueryPoints(m, 18));
}

TEST(MeshIndex, ClosestIsTheBruteForceMinimiserOnClosedAndOpenMeshes) {
  const TriangleMesh sphere = testing::Icosphere(40, 3);
  ExpectMatchesBruteForce(sphere, OracleQueryPoints(sphere, 5));
  const TriangleMesh sheet = testing::HeightField(0, 60, 0, 40, 31, 21, [](double x, double y) {
    return 2 * std::sin(x / 7) * std::cos(y / 5);
  });
  ExpectMatchesBruteForce(sheet, OracleQueryPoints(sheet, 6));
}

// Slivers: a long edge of 50 mm and a height of 50 * 10^-k mm (k = 2..9),
// still above TriangleMesh's degeneracy limit, at random orientations and
// positions. Their computed normals are off by up to ~1e-16 * 10^k, and the
// culling bounds must stay lower bounds all the same.
TEST(MeshIndex, ClosestIsTheBruteForceMinimiserOnSlivers) {
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u(-1, 1);
  TriangleMesh m;
  for (int i = 0; i < 240; ++i) {
    const Vector3d c(40 * u(rng), 40 * u(rng), 40 * u(rng));
    const Vector3d d = Vector3d(u(rng), u(rng), u(rng)).normalized();
    const Vector3d e = d.cross(Vector3d(u(rng), u(rng), u(rng))).normalized();
    const double h = 50 * std::pow(10.0, -(2 + i % 8));
    for (const Vector3d& v :
         {Vector3d(c - 25 * d), Vector3d(c + 25 * d), Vector3d(c + (u(rng) * 20) * d + h * e)})
      m.vertices.push_back(v.cast<float>());
    const auto b = static_cast<uint32_t>(3 * i);
    m.triangles.push_back({b, b + 1, b + 2});
  }
  ASSERT_LT(m.CountDegenerate(), m.num_triangles() / 4) << "most slivers must count as triangles";
  std::vector<Vector3d> pts = OracleQueryPoints(m, 32);
  // Points just off each sliver's long edge, where plane and edge bounds are closest to the truth.
  for (std::size_t t = 0; t < m.num_triangles(); t += 3) {
    const Vector3d a = V(m, m.triangles[t][0]), b = V(m, m.triangles[t][1]);
    pts.push_back(0.5 * (a + b) + 1e-3 * Vector3d(u(rng), u(rng), u(rng)));
  }
  ExpectMatchesBruteForce(m, pts);
}

// Car-body coordinates, metres from the origin: the float query point that
// Embree culls with is then off by ~1e-4 mm, and the search radius must be
// padded for the exact minimiser (and every tie) to survive the culling.
TEST(MeshIndex, ClosestIsExactFarFromTheOrigin) {
  const Eigen::Vector3f offset(4000, -3000, 2500);
  TriangleMesh sheet = testing::HeightField(0, 30, 0, 30, 31, 31, [](double x, double y) {
    return 0.3 * std::sin(x / 3) * std::cos(y / 4);
  });
  for (auto& v : sheet.vertices) v += offset;
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(0, 30), h(-0.05, 0.05), near_edge(-2e-3, 2e-3);
  std::vector<Vector3d> pts;
  for (int i = 0; i < 500; ++i)
    pts.push_back(offset.cast<double>() + Vector3d(u(rng), u(rng), 0.3 + h(rng)));
  ExpectMatchesBruteForce(sheet, pts);
  // A flat, axis-aligned sheet: the boxes are as tight as the triangles, and
  // points just above the grid lines have near-ties within 1e-4 mm. Without
  // the padding this finds a wrong triangle (checked).
  TriangleMesh flat =
      testing::HeightField(0, 30, 0, 30, 31, 31, [](double, double) { return 0.0; });
  for (auto& v : flat.vertices) v += offset;
  pts.clear();
  for (int i = 0; i < 1500; ++i) {
    const double x = std::floor(u(rng)) + near_edge(rng);
    pts.push_back(offset.cast<double>() +
                  Vector3d(i % 2 ? x : u(rng), i % 2 ? u(rng) : x, 0.2 * h(rng)));
  }
  ExpectMatchesBruteForce(flat, pts);
}

// Points near the surface of `m` at many scales, and near its vertices and
// edges, for the sign tests.
std::vector<Vector3d> SignQueryPoints(const TriangleMesh& m, uint64_t seed, int n) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> g;
  auto dir = [&] { return Vector3d(g(rng), g(rng), g(rng)).normalized(); };
  const double scales[] = {1e-5, 1e-3, 0.1, 1.0, 5.0};
  std::vector<Vector3d> pts;
  for (int i = 0; i < n; ++i) {
    const auto& tri = m.triangles[rng() % m.num_triangles()];
    const Vector3d a = V(m, tri[0]), b = V(m, tri[1]), c = V(m, tri[2]);
    const double s = u(rng), t = u(rng) * (1 - s);
    const double len = scales[rng() % 5];
    pts.push_back(a + s * (b - a) + t * (c - a) + len * dir());
    pts.push_back(a + len * dir());
    pts.push_back(a + 0.5 * (b - a) + len * dir());
  }
  return pts;
}

// A star-shaped "crumpled ball": icosphere vertices pushed in and out along
// their rays. Still closed and free of self-intersections, but full of sharp
// concave and convex edges and vertices.
TriangleMesh CrumpledBall(uint64_t seed) {
  TriangleMesh m = testing::Icosphere(20, 2);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(0.3f, 1.5f);
  for (auto& v : m.vertices) v *= u(rng);
  return m;
}

TEST(MeshIndex, SignAgreesWithTheWindingNumberOnClosedMeshes) {
  // The crumpled balls get most points: their saddle vertices are where an
  // unweighted normal sum fails (checked: it gives ~10 wrong signs here).
  const std::vector<std::pair<TriangleMesh, int>> meshes = {
      {testing::Icosphere(30, 3), 500},
      {testing::Torus(40, 12, 48, 24), 500},
      {testing::Box(Vector3d(-10, -20, -5), Vector3d(30, 10, 15)), 500},
      {CrumpledBall(1), 3000},
      {CrumpledBall(2), 3000},
      {CrumpledBall(3), 3000},
      {CrumpledBall(4), 3000}};
  int checked = 0;
  for (std::size_t k = 0; k < meshes.size(); ++k) {
    const TriangleMesh& m = meshes[k].first;
    auto index = testing::IndexOf(m);
    ASSERT_TRUE(index);
    EXPECT_EQ(index->info().boundary_edges, 0u);
    for (const Vector3d& p : SignQueryPoints(m, 100 + k, meshes[k].second)) {
      const ClosestPoint r = index->Closest(p);
      if (r.distance_mm <= 1e-6) continue;
      const bool inside = testing::WindingNumber(m, p) > 0.5;
      EXPECT_EQ(r.signed_distance_mm < 0, inside)
          << "mesh " << k << " p " << p.transpose() << " feature " << static_cast<int>(r.feature);
      ++checked;
    }
  }
  EXPECT_GT(checked, 30000);
}

TEST(MeshIndex, SignOnAnOpenSheetIsTheFaceSide) {
  const TriangleMesh sheet = testing::HeightField(0, 60, 0, 40, 61, 41, [](double x, double y) {
    return 2 * std::sin(x / 7) * std::cos(y / 5) + 0.05 * x;
  });
  auto index = testing::IndexOf(sheet);
  ASSERT_TRUE(index);
  EXPECT_GT(index->info().boundary_edges, 0u);
  int checked = 0;
  for (const Vector3d& p : SignQueryPoints(sheet, 17, 1500)) {
    // Keep to the interior so the closest point is not on the open rim.
    if (p.x() < 10 || p.x() > 50 || p.y() < 10 || p.y() > 30) continue;
    const ClosestPoint r = index->Closest(p);
    const double h = testing::MeshHeightAt(sheet, p.x(), p.y());
    if (r.distance_mm <= 1e-6) continue;
    EXPECT_EQ(r.signed_distance_mm > 0, p.z() > h) << p.transpose();
    if (r.feature == ClosestFeature::kFace) {
      EXPECT_EQ(r.signed_distance_mm > 0, (p - r.point).dot(r.normal) > 0);
    }
    ++checked;
  }
  EXPECT_GT(checked, 1000);
}

// A sheet-metal profile in the xz plane extruded along y (0..20 mm, 1 mm
// steps). The face normal is the profile's left side, (-dz, dx).
TriangleMesh Extrude(const std::vector<Eigen::Vector2d>& profile) {
  TriangleMesh m;
  const int ny = 21;
  for (int j = 0; j < ny; ++j)
    for (const auto& q : profile) m.vertices.emplace_back(q.x(), j, q.y());
  const auto np = static_cast<uint32_t>(profile.size());
  for (uint32_t j = 0; j + 1 < ny; ++j)
    for (uint32_t i = 0; i + 1 < np; ++i) {
      const uint32_t a = j * np + i, b = a + 1, c = a + np + 1, d = a + np;
      m.triangles.push_back({a, b, c});
      m.triangles.push_back({a, c, d});
    }
  return m;
}

// 2D point-in-polygon by winding number: the oracle for "below the sheet".
bool InsidePolygon(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& q) {
  double angle = 0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Eigen::Vector2d a = poly[i] - q, b = poly[(i + 1) % poly.size()] - q;
    angle += std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));
  }
  return std::abs(angle) > M_PI;
}

struct Fold {
  const char* name;
  std::vector<Eigen::Vector2d> profile;
  std::vector<Eigen::Vector2d> closure;  // walks back round the material side
};

// Points exactly on (and offset in all directions from) the shared bend
// edges and vertices of folded sheets must get the side a solid would give.
TEST(MeshIndex, SignIsRightAtSharpSheetMetalFolds) {
  using P = Eigen::Vector2d;
  const std::vector<Fold> folds = {
      {"roof 90", {P(-10, -10), P(0, 0), P(10, -10)}, {P(10, -200), P(-10, -200)}},
      {"roof acute", {P(-2, -20), P(0, 0), P(2, -20)}, {P(2, -200), P(-2, -200)}},
      {"roof hem", {P(-0.5, -10), P(0, 0), P(0.5, -10)}, {P(0.5, -200), P(-0.5, -200)}},
      {"valley acute", {P(-2, 20), P(0, 0), P(2, 20)}, {P(2, -200), P(-2, -200)}},
      {"valley obtuse", {P(-10, 2), P(0, 0), P(10, 2)}, {P(10, -200), P(-10, -200)}},
      {"L inside", {P(0, 10), P(0, 0), P(10, 0)}, {P(10, -200), P(-200, -200), P(-200, 10)}},
      {"L outside", {P(10, 0), P(0, 0), P(0, 10)}, {P(10, 10)}},
      {"hat",
       {P(-40, 0), P(-25, 0), P(-15, 20), P(15, 20), P(25, 0), P(40, 0)},
       {P(40, -200), P(-40, -200)}},
  };
  std::mt19937_64 rng(21);
  std::normal_distribution<double> g;
  const double lengths[] = {1e-5, 1e-3, 0.05, 0.7};
  int checked = 0;
  for (const Fold& fold : folds) {
    const TriangleMesh m = Extrude(fold.profile);
    auto index = testing::IndexOf(m);
    ASSERT_TRUE(index);
    std::vector<P> polygon = fold.profile;
    polygon.insert(polygon.end(), fold.closure.begin(), fold.closure.end());
    for (std::size_t i = 1; i + 1 < fold.profile.size(); ++i)  // the bends
      for (double y : {5.0, 5.5, 10.0, 13.25}) {               // on vertices and edges
        const Vector3d bend(fold.profile[i].x(), y, fold.profile[i].y());
        const ClosestPoint on = index->Closest(bend);
        EXPECT_EQ(on.distance_mm, 0.0) << fold.name;
        for (int k = 0; k < 200; ++k) {
          const Vector3d p = bend + lengths[k % 4] * Vector3d(g(rng), g(rng), g(rng)).normalized();
          const ClosestPoint r = index->Closest(p);
          if (r.distance_mm <= 1e-6) continue;
          const bool below = InsidePolygon(polygon, P(p.x(), p.z()));
          EXPECT_EQ(r.signed_distance_mm < 0, below)
              << fold.name << " p " << p.transpose() << " feature " << static_cast<int>(r.feature);
          ++checked;
        }
      }
  }
  EXPECT_GT(checked, 8000);
}

TEST(MeshIndex, VertexPseudonormalsMadeOnFirstUseAgreeAcrossThreads) {
  // Points beyond the corners of a crumpled ball (its saddle vertices need
  // the angle weights), each asked many times in a shuffled order, so that
  // threads ask for the same vertex normals at once; a fresh index per run.
  const TriangleMesh m = CrumpledBall(2);
  std::vector<Eigen::Vector3f> pts;
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> out(0.01, 0.3);
  for (int rep = 0; rep < 40; ++rep)
    for (const Eigen::Vector3f& v : m.vertices) pts.push_back(v * static_cast<float>(1 + out(rng)));
  std::shuffle(pts.begin(), pts.end(), rng);
  const PointCloud cloud = PointCloud::Unorganized(std::move(pts));
  std::vector<double> want;
  for (const Eigen::Vector3f& p : cloud.points) {
    const ClosestPoint r = testing::IndexOf(m)->Closest(p.cast<double>());
    want.push_back(r.signed_distance_mm);
    if (want.size() == 200) break;  // a fresh index per point: the serial oracle
  }
  int at_vertex = 0;
  for (int threads : {1, 2, 8}) {
    auto index = testing::IndexOf(m);
    ASSERT_TRUE(index);
    BatchQuerySettings s;
    s.threads = threads;
    auto got = QueryClosest(*index, cloud, Eigen::Isometry3d::Identity(), s);
    ASSERT_TRUE(got.ok());
    for (std::size_t i = 0; i < want.size(); ++i) EXPECT_EQ((*got)[i].signed_distance_mm, want[i]);
    for (const ClosestPoint& r : *got) {
      at_vertex += IsVertex(r.feature);
      EXPECT_GT(r.signed_distance_mm, 0) << "outside the ball";
    }
  }
  EXPECT_GT(at_vertex, 1000);
}

TEST(MeshIndex, PyramidApexAndPitUseTheVertexPseudonormal) {
  for (double k : {0.3, 1.0, 4.0}) {
    for (double s : {-1.0, 1.0}) {  // apex (s = -1) and pit (s = +1)
      const TriangleMesh m = testing::HeightField(
          -10, 10, -10, 10, 21, 21,
          [&](double x, double y) { return s * k * std::max(std::abs(x), std::abs(y)); });
      auto index = testing::IndexOf(m);
      ASSERT_TRUE(index);
      std::mt19937_64 rng(static_cast<uint64_t>(k * 10 + s));
      std::normal_distribution<double> g;
      for (int i = 0; i < 400; ++i) {
        const Vector3d p = (i % 2 ? 1e-3 : 0.5) * Vector3d(g(rng), g(rng), g(rng)).normalized();
        const ClosestPoint r = index->Closest(p);
        if (r.distance_mm <= 1e-6) continue;
        EXPECT_EQ(r.signed_distance_mm > 0, p.z() > testing::MeshHeightAt(m, p.x(), p.y()))
            << "k " << k << " s " << s << " p " << p.transpose();
      }
    }
  }
}

// Random saddle and cone vertices: fans of 3-9 triangles with uneven
// angles and steep slopes, where an unweighted normal sum is known to give
// the wrong side (Bærentzen & Aanæs, §3). All fans share one mesh, 100 mm apart.
TEST(MeshIndex, SignIsRightAtRandomFanVertices) {
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> g;
  TriangleMesh all;
  std::vector<TriangleMesh> fans;
  for (int f = 0; f < 150; ++f) {
    const int k = 3 + static_cast<int>(rng() % 7);
    std::vector<double> az;  // azimuths with every gap in (0, 0.8 pi)
    do {
      az.clear();
      for (int i = 0; i < k; ++i) az.push_back(2 * M_PI * u(rng));
      std::sort(az.begin(), az.end());
      az.push_back(az[0] + 2 * M_PI);
    } while ([&] {
      for (int i = 0; i < k; ++i)
        if (az[i + 1] - az[i] > 0.8 * M_PI || az[i + 1] - az[i] < 0.05) return true;
      return false;
    }());
    TriangleMesh fan;
    const Eigen::Vector3f centre(100.f * f, 0, 0);
    fan.vertices.push_back(centre);
    for (int i = 0; i < k; ++i)
      fan.vertices.push_back(centre + Eigen::Vector3f(10 * std::cos(az[i]), 10 * std::sin(az[i]),
                                                      10 * std::tan((u(rng) - 0.5) * 2.6)));
    for (int i = 0; i < k; ++i)
      fan.triangles.push_back(
          {0u, static_cast<uint32_t>(1 + i), static_cast<uint32_t>(1 + (i + 1) % k)});
    const auto base = static_cast<uint32_t>(all.vertices.size());
    all.vertices.insert(all.vertices.end(), fan.vertices.begin(), fan.vertices.end());
    for (const auto& t : fan.triangles)
      all.triangles.push_back({base + t[0], base + t[1], base + t[2]});
    fans.push_back(std::move(fan));
  }
  auto index = testing::IndexOf(all);
  ASSERT_TRUE(index);
  int checked = 0, at_vertex = 0;
  for (const TriangleMesh& fan : fans) {
    const Vector3d centre = V(fan, 0);
    for (int i = 0; i < 300; ++i) {
      const Vector3d p =
          centre + (i % 2 ? 1e-3 : 0.3) * Vector3d(g(rng), g(rng), g(rng)).normalized();
      const ClosestPoint r = index->Closest(p);
      if (r.distance_mm <= 1e-6) continue;
      const double h = testing::MeshHeightAt(fan, p.x(), p.y());
      EXPECT_EQ(r.signed_distance_mm > 0, p.z() > h)
          << p.transpose() << " feature " << static_cast<int>(r.feature);
      ++checked;
      at_vertex += IsVertex(r.feature) ? 1 : 0;
    }
  }
  EXPECT_GT(checked, 40000);
  EXPECT_GT(at_vertex, 300);
}

TEST(MeshIndex, UnweldedSoupStillSignsByTopology) {
  // An STL-style soup: every triangle has its own three vertices.
  const TriangleMesh welded = testing::Box(Vector3d(0, 0, 0), Vector3d(10, 10, 10));
  TriangleMesh soup;
  for (const auto& t : welded.triangles) {
    const auto b = static_cast<uint32_t>(soup.vertices.size());
    for (uint32_t v : t) soup.vertices.push_back(welded.vertices[v]);
    soup.triangles.push_back({b, b + 1, b + 2});
  }
  auto index = testing::IndexOf(soup);
  ASSERT_TRUE(index);
  EXPECT_EQ(index->info().welded_vertices, 36u - 8u);
  EXPECT_EQ(index->info().boundary_edges, 0u);
  // Diagonally out of and into each corner: the vertex pseudonormal decides.
  for (int c = 0; c < 8; ++c) {
    const Vector3d corner(c & 1 ? 10 : 0, c & 2 ? 10 : 0, c & 4 ? 10 : 0);
    const Vector3d out = (corner - Vector3d(5, 5, 5)).normalized();
    EXPECT_GT(index->Closest(corner + 0.1 * out).signed_distance_mm, 0);
    EXPECT_LT(index->Closest(corner - 0.1 * out).signed_distance_mm, 0);
    // Outside beyond one face but near the corner: still +.
    EXPECT_GT(index->Closest(corner + Vector3d(0.2 * out.x(), 0.01 * out.y(), 0.01 * out.z()))
                  .signed_distance_mm,
              0);
  }
}

TEST(MeshIndex, DegenerateAndNonManifoldTrianglesDoNotBreakQueries) {
  TriangleMesh m = testing::HeightField(0, 10, 0, 10, 11, 11, [](double, double) { return 0.0; });
  const auto n = static_cast<uint32_t>(m.vertices.size());
  m.vertices.emplace_back(5, 5, 0);
  m.triangles.push_back({0, 1, 2});    // a collinear sliver along y = 0
  m.triangles.push_back({n, n, n});    // a point
  m.triangles.push_back({12, 13, n});  // shares edge 12-13: now non-manifold
  auto index = testing::IndexOf(m);
  ASSERT_TRUE(index);
  EXPECT_EQ(index->info().degenerate_triangles, 2u);
  EXPECT_GE(index->info().nonmanifold_edges, 1u);
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-2, 12);
  for (int i = 0; i < 300; ++i) {
    const Vector3d p(u(rng), u(rng), u(rng) - 5);
    const ClosestPoint r = index->Closest(p);
    const Brute want = BruteForce(m, p);
    EXPECT_EQ(r.distance_mm, std::sqrt(want.d2));
    EXPECT_EQ(r.triangle_id, want.triangle);
  }
}

TEST(MeshIndex, TopologyAndDegenerateCountAreTheMeshCounts) {
  // An open sheet with a fin (a non-manifold edge), a sliver and a point
  // triangle; the same mesh as a soup, whose unwelded edges are all boundary.
  TriangleMesh m = testing::HeightField(
      0, 10, 0, 10, 11, 11, [](double x, double y) { return 0.3 * std::sin(x) * std::cos(y); });
  const auto n = static_cast<uint32_t>(m.vertices.size());
  m.vertices.emplace_back(5, 5, 3);
  m.triangles.push_back({0, 1, 2});
  m.triangles.push_back({n, n, n});
  m.triangles.push_back({12, 13, n});
  TriangleMesh soup;
  for (const auto& t : m.triangles) {
    const auto b = static_cast<uint32_t>(soup.vertices.size());
    for (uint32_t v : t) soup.vertices.push_back(m.vertices[v]);
    soup.triangles.push_back({b, b + 1, b + 2});
  }
  for (const TriangleMesh* mesh : {&m, &soup}) {
    auto index = testing::IndexOf(*mesh);
    ASSERT_TRUE(index);
    const MeshTopology want = AnalyzeTopology(*mesh);
    EXPECT_EQ(index->Topology().boundary_edges, want.boundary_edges);
    EXPECT_EQ(index->Topology().nonmanifold_edges, want.nonmanifold_edges);
    EXPECT_EQ(index->info().degenerate_triangles, mesh->CountDegenerate());
  }
  EXPECT_EQ(AnalyzeTopology(soup).boundary_edges, 3 * soup.triangles.size());
  EXPECT_GE(AnalyzeTopology(m).nonmanifold_edges, 1u);
}

TEST(MeshIndex, BuildRejectsBadMeshesAndSettings) {
  EXPECT_EQ(MeshIndex::Build(TriangleMesh{}).status().code(), absl::StatusCode::kInvalidArgument);
  TriangleMesh nan = testing::Box(Vector3d::Zero(), Vector3d::Ones());
  nan.vertices[3].x() = NAN;
  EXPECT_EQ(MeshIndex::Build(nan).status().code(), absl::StatusCode::kInvalidArgument);
  TriangleMesh bad_index = testing::Box(Vector3d::Zero(), Vector3d::Ones());
  bad_index.triangles[0][1] = 99;
  EXPECT_EQ(MeshIndex::Build(bad_index).status().code(), absl::StatusCode::kInvalidArgument);
  TriangleMesh flat;
  flat.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  flat.triangles = {{0, 1, 2}};
  EXPECT_EQ(MeshIndex::Build(flat).status().code(), absl::StatusCode::kInvalidArgument);
  MeshIndexSettings s;
  s.build_threads = -1;
  EXPECT_EQ(MeshIndex::Build(testing::Box(Vector3d::Zero(), Vector3d::Ones()), s).status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST(MeshIndex, MaxDistanceNonFinitePointsAndMemory) {
  auto index = testing::IndexOf(testing::Box(Vector3d::Zero(), Vector3d::Constant(10)));
  ASSERT_TRUE(index);
  EXPECT_TRUE(index->Closest(Vector3d(5, 5, 12), 2.5).matched());
  EXPECT_NEAR(index->Closest(Vector3d(5, 5, 12), 2.5).signed_distance_mm, 2.0, 1e-12);
  EXPECT_TRUE(index->Closest(Vector3d(5, 5, 12), 2.0).matched()) << "the limit is inclusive";
  const ClosestPoint far = index->Closest(Vector3d(5, 5, 12), 1.9);
  EXPECT_FALSE(far.matched());
  EXPECT_TRUE(std::isnan(far.distance_mm));
  EXPECT_TRUE(std::isnan(far.signed_distance_mm));
  EXPECT_FALSE(index->Closest(Vector3d(NAN, 0, 0)).matched());
  EXPECT_FALSE(index->Closest(Vector3d(0, INFINITY, 0)).matched());
  EXPECT_FALSE(index->Closest(Vector3d(5, 5, 5), NAN).matched());
  EXPECT_NEAR(index->Closest(Vector3d(5, 5, 5)).signed_distance_mm, -5.0, 1e-12);
  EXPECT_GT(index->memory_bytes(), 12 * sizeof(Triangle) + 8 * sizeof(Eigen::Vector3f));
}

PointCloud OrganizedCloudNear(const TriangleMesh& m, uint32_t w, uint32_t h, uint64_t seed) {
  // A grid of points above a height field, with NaN holes, like a scan.
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0, 0.3);
  PointCloud c = PointCloud::Organized(w, h);
  const Bounds3 b = ComputeBounds(m);
  for (uint32_t r = 0; r < h; ++r)
    for (uint32_t col = 0; col < w; ++col) {
      if (rng() % 10 == 0) continue;  // a hole
      const double x = b.min.x() + (b.max.x() - b.min.x()) * (col + 0.5) / w;
      const double y = b.min.y() + (b.max.y() - b.min.y()) * (r + 0.5) / h;
      c.points[r * w + col] = Eigen::Vector3f(x, y, testing::MeshHeightAt(m, x, y) + g(rng));
    }
  return c;
}

void ExpectIdentical(const std::vector<ClosestPoint>& a, const std::vector<ClosestPoint>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].triangle_id, b[i].triangle_id) << i;
    if (!a[i].matched()) continue;
    ASSERT_EQ(a[i].point, b[i].point) << i;
    ASSERT_EQ(a[i].distance_mm, b[i].distance_mm) << i;
    ASSERT_EQ(a[i].signed_distance_mm, b[i].signed_distance_mm) << i;
    ASSERT_EQ(a[i].feature, b[i].feature) << i;
  }
}

TEST(MeshIndexBatch, OneAndManyThreadsAndCoherentStartGiveIdenticalResults) {
  const TriangleMesh sheet = testing::HeightField(
      0, 30, 0, 20, 31, 21, [](double x, double y) { return std::sin(x / 4) * std::cos(y / 3); });
  auto index = testing::IndexOf(sheet);
  ASSERT_TRUE(index);
  const PointCloud organized = OrganizedCloudNear(sheet, 60, 40, 1);
  // Unorganized: the same points shuffled (exercises the Morton order).
  std::vector<Eigen::Vector3f> shuffled = organized.points;
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937_64(2));
  const PointCloud unorganized = PointCloud::Unorganized(shuffled);
  const Eigen::Isometry3d mesh_from_points =
      Eigen::Translation3d(0.5, -0.25, 0.1) * Eigen::AngleAxisd(0.01, Vector3d::UnitZ());
  for (const PointCloud* cloud : {&organized, &unorganized}) {
    BatchQuerySettings serial;
    serial.threads = 1;
    serial.coherent_start = false;
    serial.max_distance_mm = 0.6;
    auto reference = QueryClosest(*index, *cloud, mesh_from_points, serial);
    ASSERT_TRUE(reference.ok()) << reference.status();
    std::size_t matched = 0, unmatched_valid = 0;
    for (std::size_t i = 0; i < cloud->size(); ++i) {
      const ClosestPoint single =
          index->Closest(mesh_from_points * cloud->points[i].cast<double>(), 0.6);
      EXPECT_EQ((*reference)[i].triangle_id, single.triangle_id);
      if (single.matched()) {
        EXPECT_EQ((*reference)[i].distance_mm, single.distance_mm);
        ++matched;
      } else if (PointCloud::IsValid(cloud->points[i])) {
        ++unmatched_valid;
      }
    }
    EXPECT_GT(matched, 1000u);
    EXPECT_GT(unmatched_valid, 10u) << "some points must lie beyond max_distance";
    for (int threads : {1, 2, 0})
      for (bool coherent : {false, true}) {
        BatchQuerySettings s = serial;
        s.threads = threads;
        s.coherent_start = coherent;
        auto got = QueryClosest(*index, *cloud, mesh_from_points, s);
        ASSERT_TRUE(got.ok());
        ExpectIdentical(*reference, *got);
      }
    // And in every instruction set and kind of build.
    for (const MeshIndexSettings& settings : AllSearches()) {
      auto other = MeshIndex::Build(sheet, settings);
      ASSERT_TRUE(other.ok()) << other.status();
      BatchQuerySettings s = serial;
      s.threads = 2;
      s.coherent_start = true;
      auto got = QueryClosest(**other, *cloud, mesh_from_points, s);
      ASSERT_TRUE(got.ok());
      ExpectIdentical(*reference, *got);
    }
  }
}

TEST(MeshIndex, TheSearchIsaIsReportedAndAnUnsupportedOneRejected) {
  const TriangleMesh box = testing::Box(Vector3d::Zero(), Vector3d::Ones());
  MeshIndexSettings s;
  s.search_isa = SearchIsa::kSse2;
  auto sse2 = MeshIndex::Build(box, s);
  ASSERT_TRUE(sse2.ok());
  EXPECT_STREQ((*sse2)->info().search_isa, "sse2");
  EXPECT_GE((*sse2)->info().bvh_nodes, 1u);
  s.search_isa = SearchIsa::kAvx2;
  auto avx2 = MeshIndex::Build(box, s);
  if (SearchIsaSupported(SearchIsa::kAvx2)) {
    ASSERT_TRUE(avx2.ok());
    EXPECT_STREQ((*avx2)->info().search_isa, "avx2");
  } else {
    EXPECT_EQ(avx2.status().code(), absl::StatusCode::kInvalidArgument);
  }
  auto automatic = MeshIndex::Build(box);
  ASSERT_TRUE(automatic.ok());
  EXPECT_STREQ((*automatic)->info().search_isa, SearchIsaName(SearchIsa::kAuto));
}

TEST(MeshIndexBatch, CancelAndBadInput) {
  auto index = testing::IndexOf(testing::Box(Vector3d::Zero(), Vector3d::Constant(10)));
  ASSERT_TRUE(index);
  PointCloud cloud =
      PointCloud::Unorganized(std::vector<Eigen::Vector3f>(5000, Eigen::Vector3f(1, 2, 3)));
  std::atomic<bool> cancel{true};
  EXPECT_EQ(QueryClosest(*index, cloud, Eigen::Isometry3d::Identity(), {}, &cancel).status().code(),
            absl::StatusCode::kCancelled);
  cancel = false;
  EXPECT_TRUE(QueryClosest(*index, cloud, Eigen::Isometry3d::Identity(), {}, &cancel).ok());
  BatchQuerySettings bad;
  bad.threads = -2;
  EXPECT_EQ(QueryClosest(*index, cloud, Eigen::Isometry3d::Identity(), bad).status().code(),
            absl::StatusCode::kInvalidArgument);
  bad = {};
  bad.max_distance_mm = NAN;
  EXPECT_EQ(QueryClosest(*index, cloud, Eigen::Isometry3d::Identity(), bad).status().code(),
            absl::StatusCode::kInvalidArgument);
  bad.max_distance_mm = -1;
  EXPECT_EQ(QueryClosest(*index, cloud, Eigen::Isometry3d::Identity(), bad).status().code(),
            absl::StatusCode::kInvalidArgument);
  Eigen::Isometry3d nan_pose = Eigen::Isometry3d::Identity();
  nan_pose.translation().x() = NAN;
  EXPECT_EQ(QueryClosest(*index, cloud, nan_pose, {}).status().code(),
            absl::StatusCode::kInvalidArgument);
  cloud.width = 7;  // width * height != size
  EXPECT_EQ(QueryClosest(*index, cloud, Eigen::Isometry3d::Identity(), {}).status().code(),
            absl::StatusCode::kInvalidArgument);
  auto empty = QueryClosest(*index, PointCloud{}, Eigen::Isometry3d::Identity(), {});
  ASSERT_TRUE(empty.ok());
  EXPECT_TRUE(empty->empty());
}

TEST(MeshIndexBatch, QueryClosestEachCallsTheSinkOnceForEveryIndex) {
  const TriangleMesh sheet = testing::HeightField(
      0, 30, 0, 20, 31, 21, [](double x, double y) { return 0.5 * std::sin(x / 5) + 0.1 * y; });
  auto index = testing::IndexOf(sheet);
  ASSERT_TRUE(index);
  PointCloud cloud = OrganizedCloudNear(sheet, 50, 30, 3);
  for (std::size_t i = 0; i < cloud.size(); i += 11)
    cloud.points[i] = Eigen::Vector3f::Constant(NAN);
  std::vector<Eigen::Vector3f> shuffled = cloud.points;
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937_64(4));
  const PointCloud unorganized = PointCloud::Unorganized(shuffled);
  const PointCloud& organized = cloud;
  for (const PointCloud* points : {&organized, &unorganized}) {
    BatchQuerySettings s;
    s.threads = 2;
    s.max_distance_mm = 0.6;
    std::vector<std::atomic<int>> calls(points->size());
    std::vector<ClosestPoint> streamed(points->size());
    const absl::Status st = QueryClosestEach(*index, *points, Eigen::Isometry3d::Identity(), s,
                                             nullptr, [&](std::size_t i, const ClosestPoint& r) {
                                               calls[i].fetch_add(1);
                                               streamed[i] = r;
                                             });
    ASSERT_TRUE(st.ok()) << st;
    for (std::size_t i = 0; i < points->size(); ++i) {
      ASSERT_EQ(calls[i].load(), 1) << i;
      const ClosestPoint single = index->Closest(points->points[i].cast<double>(), 0.6);
      EXPECT_EQ(streamed[i].triangle_id, single.triangle_id) << i;
      if (!PointCloud::IsValid(points->points[i])) {
        EXPECT_FALSE(streamed[i].matched()) << i;
      }
    }
  }
  std::atomic<bool> cancel{true};
  std::atomic<int> sunk{0};
  EXPECT_EQ(QueryClosestEach(*index, cloud, Eigen::Isometry3d::Identity(), {}, &cancel,
                             [&](std::size_t, const ClosestPoint&) { ++sunk; })
                .code(),
            absl::StatusCode::kCancelled);
  EXPECT_LT(sunk.load(), static_cast<int>(cloud.size()));
}

TEST(MeshIndex, OneShotCallsBuildHintCertificatesOnlyWithEnoughPointsPerTriangle) {
  EXPECT_FALSE(CertificatesPayOnce(1'000'000, 180'000));  // the whole-command bench
  EXPECT_TRUE(CertificatesPayOnce(786'432, 20'000));      // a 1024x768 view on a small part
  EXPECT_TRUE(CertificatesPayOnce(16, 1));
  EXPECT_FALSE(CertificatesPayOnce(15, 1));
}

}  // namespace
}  // namespace surfinspect
