// Covers core/distance/hint_certificate.cpp: each certificate's ring holds
// every triangle that shares a vertex position, its reach is a lower bound
// on the distance from its anchor to every triangle outside the ring (brute
// force), and queries answered through it equal the tree's and brute
// force's.
#include "core/distance/hint_certificate.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <random>
#include <set>

#include "core/distance/mesh_index.h"
#include "tests/support/test_meshes.h"

namespace surfinspect {
namespace {

using Eigen::Vector3d;

Vector3d V(const TriangleMesh& m, uint32_t i) { return m.vertices[i].cast<double>(); }

std::unique_ptr<MeshIndex> BuildWith(const TriangleMesh& mesh, bool certificates) {
  MeshIndexSettings s;
  s.hint_certificates = certificates;
  auto index = MeshIndex::Build(mesh, s);
  EXPECT_TRUE(index.ok()) << index.status();
  return index.ok() ? *std::move(index) : nullptr;
}

// The mesh ids of the triangles in a certificate's lanes (which hold
// positions in the index's order).
std::set<uint32_t> RingOf(const MeshIndex& index, const HintCertificate& c) {
  std::set<uint32_t> ring;
  for (int j = 0; j < c.blocks; ++j)
    for (int lane = 0; lane < wide::kLeafWidth; ++lane)
      if (c.lanes[j] >> lane & 1u)
        ring.insert(index.mesh_triangle(index.bvh().blocks()[c.block[j]].triangle[lane]));
  return ring;
}

const HintCertificate& CertificateOf(const MeshIndex& index, uint32_t triangle) {
  return index.hint_certificates()->of(index.position_of(triangle));
}

double TriangleDistance(const TriangleMesh& m, uint32_t t, const Vector3d& p) {
  const auto& tri = m.triangles[t];
  return std::sqrt(
      ClosestPointOnTriangle(p, V(m, tri[0]), V(m, tri[1]), V(m, tri[2])).squared_distance);
}

// For every certifiable triangle T: T and every triangle sharing a vertex
// position are in the ring, and every triangle outside the ring is at
// least the reach from the anchor. Returns how many triangles can certify.
std::size_t ExpectSoundCertificates(const TriangleMesh& m) {
  auto index = BuildWith(m, true);
  if (!index) return 0;
  const HintCertificates* certificates = index->hint_certificates();
  EXPECT_NE(certificates, nullptr);
  if (!certificates) return 0;
  std::size_t certifiable = 0;
  for (uint32_t t = 0; t < m.num_triangles(); ++t) {
    const HintCertificate& c = CertificateOf(*index, t);
    if (c.reach_mm <= 0) continue;
    ++certifiable;
    const std::set<uint32_t> ring = RingOf(*index, c);
    const auto& tri = m.triangles[t];
    const Vector3d anchor(c.anchor[0], c.anchor[1], c.anchor[2]);
    EXPECT_TRUE(ring.count(t)) << t;
    for (uint32_t u = 0; u < m.num_triangles(); ++u) {
      bool shares = false;
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) shares |= m.vertices[tri[k]] == m.vertices[m.triangles[u][l]];
      if (shares) {
        EXPECT_TRUE(ring.count(u)) << "triangle " << u << " shares a vertex with " << t;
        continue;
      }
      if (ring.count(u)) continue;
      if (!(TriangleDistance(m, u, anchor) >= c.reach_mm)) {
        ADD_FAILURE() << "triangle " << u << " is nearer to " << t
                      << "'s anchor than its reach: " << TriangleDistance(m, u, anchor) << " < "
                      << c.reach_mm << " ring " << ring.size();
        return 0;
      }
    }
  }
  return certifiable;
}

TEST(HintCertificates, ReachIsALowerBoundOutsideTheRing) {
  // Closed, open, a soup of separate triangles (rings of one), and a
  // double sheet 0.05 mm apart, whose reaches must stay below the gap.
  EXPECT_GT(ExpectSoundCertificates(testing::Icosphere(20, 2)), 300u);
  EXPECT_GT(ExpectSoundCertificates(testing::Torus(30, 10, 24, 12)), 500u);
  const auto wave = [](double x, double y) { return std::sin(x / 3) * std::cos(y / 4); };
  TriangleMesh sheets = testing::HeightField(0, 20, 0, 20, 11, 11, wave);
  const TriangleMesh upper = testing::HeightField(
      0, 20, 0, 20, 11, 11, [&](double x, double y) { return wave(x, y) + 0.05; });
  const auto offset = static_cast<uint32_t>(sheets.vertices.size());
  sheets.vertices.insert(sheets.vertices.end(), upper.vertices.begin(), upper.vertices.end());
  for (Triangle t : upper.triangles)
    sheets.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  ExpectSoundCertificates(sheets);
  auto index = BuildWith(sheets, true);
  ASSERT_TRUE(index);
  for (uint32_t t = 0; t < sheets.num_triangles(); ++t)
    EXPECT_LE(CertificateOf(*index, t).reach_mm, 0.05f) << t;
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<float> u(0, 50), d(-3, 3);
  TriangleMesh soup;
  for (uint32_t i = 0; i < 150; ++i) {
    const Eigen::Vector3f c(u(rng), u(rng), u(rng));
    for (int k = 0; k < 3; ++k)
      soup.vertices.push_back(c + Eigen::Vector3f(d(rng), d(rng), d(rng)));
    soup.triangles.push_back({3 * i, 3 * i + 1, 3 * i + 2});
  }
  EXPECT_GT(ExpectSoundCertificates(soup), 50u);
}

// A fan of 64 triangles around one vertex spreads its ring over more
// blocks than a certificate holds: those triangles get none.
TEST(HintCertificates, AHighValenceVertexLeavesItsFanUncertified) {
  TriangleMesh fan;
  fan.vertices.emplace_back(0, 0, 0);
  const int n = 64;
  for (int i = 0; i < n; ++i)
    fan.vertices.emplace_back(10 * std::cos(2 * M_PI * i / n), 10 * std::sin(2 * M_PI * i / n), 0);
  for (uint32_t i = 0; i < n; ++i) fan.triangles.push_back({0, 1 + i, 1 + (i + 1) % n});
  auto index = BuildWith(fan, true);
  ASSERT_TRUE(index);
  for (uint32_t t = 0; t < fan.num_triangles(); ++t)
    EXPECT_EQ(CertificateOf(*index, t).reach_mm, 0.f) << t;
  EXPECT_EQ(index->info().certifiable_triangles, 0u);
  // Still exact with any hint.
  const ClosestPoint want = index->Closest(Vector3d(3, 1, 0.5));
  for (uint32_t hint = 0; hint < fan.num_triangles(); ++hint)
    EXPECT_EQ(index->Closest(Vector3d(3, 1, 0.5), INFINITY, hint).triangle_id, want.triangle_id);
}

// Points within +-0.4 mm of a torus of ~1.3 mm triangles, in scan order and
// shuffled: with the certificates most queries skip the tree, and every
// result is the same, bit for bit, as without them and as brute force on a
// sample.
TEST(HintCertificates, CertifiedBatchResultsEqualTheTreeAndBruteForce) {
  const TriangleMesh torus = testing::Torus(40, 12, 192, 60);
  auto on = BuildWith(torus, true), off = BuildWith(torus, false);
  ASSERT_TRUE(on && off);
  EXPECT_GT(on->info().certifiable_triangles, torus.num_triangles() * 9 / 10);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> offset(-0.4, 0.4);
  const int side = 300;
  std::vector<Eigen::Vector3f> grid;
  for (int r = 0; r < side; ++r)
    for (int k = 0; k < side; ++k) {
      const double a = 2 * M_PI * (k + 0.5) / side, b = 2 * M_PI * (r + 0.5) / side;
      const Vector3d dir(std::cos(a) * std::cos(b), std::sin(a) * std::cos(b), std::sin(b));
      const Vector3d centre(40 * std::cos(a), 40 * std::sin(a), 0);
      grid.push_back((centre + (12 + offset(rng)) * dir).cast<float>());
    }
  std::vector<Eigen::Vector3f> shuffled = grid;
  std::shuffle(shuffled.begin(), shuffled.end(), rng);
  PointCloud organized = PointCloud::Organized(side, side);
  organized.points = grid;
  for (const PointCloud& cloud : {organized, PointCloud::Unorganized(shuffled)}) {
    BatchQueryTiming timing_on, timing_off;
    std::vector<ClosestPoint> got(cloud.size()), want(cloud.size());
    ASSERT_TRUE(QueryClosestEach(
                    *on, cloud, Eigen::Isometry3d::Identity(), {}, nullptr,
                    [&](std::size_t i, const ClosestPoint& r) { got[i] = r; }, &timing_on)
                    .ok());
    ASSERT_TRUE(QueryClosestEach(
                    *off, cloud, Eigen::Isometry3d::Identity(), {}, nullptr,
                    [&](std::size_t i, const ClosestPoint& r) { want[i] = r; }, &timing_off)
                    .ok());
    EXPECT_GT(timing_on.certified_points, cloud.size() * 3 / 4);
    EXPECT_GT(timing_on.hint_alone_points, cloud.size() / 3);
    EXPECT_EQ(timing_off.certified_points, 0u);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      ASSERT_EQ(got[i].triangle_id, want[i].triangle_id) << i;
      ASSERT_EQ(got[i].distance_mm, want[i].distance_mm) << i;
      ASSERT_EQ(got[i].signed_distance_mm, want[i].signed_distance_mm) << i;
      ASSERT_EQ(got[i].point, want[i].point) << i;
      ASSERT_EQ(got[i].feature, want[i].feature) << i;
    }
    for (std::size_t i = 0; i < cloud.size(); i += 97) {
      const Vector3d p = cloud.points[i].cast<double>();
      uint32_t best = UINT32_MAX;
      double best_d2 = INFINITY;
      for (uint32_t t = 0; t < torus.num_triangles(); ++t) {
        const auto& tri = torus.triangles[t];
        const double d2 =
            ClosestPointOnTriangle(p, V(torus, tri[0]), V(torus, tri[1]), V(torus, tri[2]))
                .squared_distance;
        if (d2 < best_d2) best_d2 = d2, best = t;
      }
      EXPECT_EQ(got[i].triangle_id, best) << i;
      EXPECT_EQ(got[i].distance_mm, std::sqrt(best_d2)) << i;
    }
  }
}

TEST(HintCertificates, CertifiesOnlyWithAMarginBelowTheReach) {
  HintCertificate c;
  c.anchor[0] = 100;
  c.reach_mm = 1.0f;
  const Vector3d p(100.3, 0, 0);  // 0.3 mm from the anchor
  EXPECT_TRUE(c.Certifies(p, 0.6999, 100));
  EXPECT_FALSE(c.Certifies(p, 0.7, 100));
  EXPECT_FALSE(c.Certifies(p, 0.69999999, 1e3));  // the margin grows with the coordinates
  EXPECT_FALSE(c.Certifies(Vector3d(101, 0, 0), 0, 100));
  c.reach_mm = 0;
  EXPECT_FALSE(c.Certifies(Vector3d(100, 0, 0), 0, 0));
}

}  // namespace
}  // namespace surfinspect
