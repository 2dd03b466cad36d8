// Covers core/distance/hint_alone.cpp: whenever RingIsFarther proves a
// triangle's ring farther from a point than the triangle, brute force over
// the ring agrees, strictly (so ties cannot flip), on smooth, flat, folded
// and crumpled meshes and on points near edges; triangles whose ring folds
// over them, duplicates and slivers get no proof.
#include "core/distance/hint_alone.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <map>
#include <random>
#include <tuple>

#include "core/distance/point_triangle.h"
#include "tests/support/test_meshes.h"

namespace surfinspect {
namespace {

using Eigen::Vector3d;

Vector3d V(const TriangleMesh& m, uint32_t i) { return m.vertices[i].cast<double>(); }

// Each vertex to the lowest index at its position, as MeshIndex welds.
std::vector<uint32_t> Weld(const TriangleMesh& m) {
  std::map<std::tuple<float, float, float>, uint32_t> first;
  std::vector<uint32_t> weld(m.vertices.size());
  for (uint32_t i = 0; i < m.vertices.size(); ++i) {
    const auto& v = m.vertices[i];
    weld[i] = first.emplace(std::make_tuple(v.x(), v.y(), v.z()), i).first->second;
  }
  return weld;
}

// The triangles sharing a vertex position with t, by brute force.
std::vector<uint32_t> Ring(const TriangleMesh& m, const std::vector<uint32_t>& weld, uint32_t t) {
  std::vector<uint32_t> ring;
  for (uint32_t u = 0; u < m.num_triangles(); ++u)
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k)
        if (weld[m.triangles[u][i]] == weld[m.triangles[t][k]] &&
            (ring.empty() || ring.back() != u))
          ring.push_back(u);
  return ring;
}

Vector3d Normal(const TriangleMesh& m, uint32_t t) {
  const auto& tri = m.triangles[t];
  return (V(m, tri[1]) - V(m, tri[0])).cross(V(m, tri[2]) - V(m, tri[0])).normalized();
}

double D2(const TriangleMesh& m, uint32_t t, const Vector3d& p) {
  const auto& tri = m.triangles[t];
  return ClosestPointOnTriangle(p, V(m, tri[0]), V(m, tri[1]), V(m, tri[2])).squared_distance;
}

struct Tally {
  int proofs = 0, valid = 0;
};

// Points over every triangle's face (inner points and points 1e-6..1e-2 of
// an edge away from it), 1e-6 to 2 mm off either side: each proof must hold
// against every ring triangle by brute force.
Tally ExpectSoundProofs(const TriangleMesh& m, uint64_t seed) {
  const std::vector<uint32_t> weld = Weld(m);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  const double offsets[] = {1e-6, 1e-3, 0.05, 0.3, 2.0};
  Tally tally;
  for (uint32_t t = 0; t < m.num_triangles(); ++t) {
    const std::vector<uint32_t> ring = Ring(m, weld, t);
    const Vector3d n = Normal(m, t);
    const HintRise rise = ComputeHintRise(m, weld, t, n, ring.data(), ring.size());
    if (!rise.valid) continue;
    ++tally.valid;
    const auto& tri = m.triangles[t];
    const Vector3d a[3] = {V(m, tri[0]), V(m, tri[1]), V(m, tri[2])};
    for (int i = 0; i < 12; ++i) {
      double s = u(rng), r = u(rng) * (1 - s);
      if (i % 3 == 0) r = std::pow(10.0, -2 - 4 * u(rng));  // close to edge AB
      const Vector3d on_face = a[0] + s * (a[1] - a[0]) + r * (a[2] - a[0]);
      const Vector3d p = on_face + (i % 2 ? 1 : -1) * offsets[i % 5] * n;
      const PointTriangleResult mine = ClosestPointOnTriangle(p, a[0], a[1], a[2]);
      if (mine.feature != ClosestFeature::kFace) continue;
      if (!RingIsFarther(rise, p, mine.point, std::sqrt(mine.squared_distance), n, m, t)) continue;
      ++tally.proofs;
      for (uint32_t other : ring) {
        if (other == t) continue;
        if (!(D2(m, other, p) > mine.squared_distance)) {
          ADD_FAILURE() << "triangle " << other << " is as close to " << p.transpose()
                        << " as triangle " << t << ", which claimed to be alone";
          return tally;
        }
      }
    }
  }
  return tally;
}

TEST(HintAlone, ProofsHoldAgainstTheRingByBruteForce) {
  // Smooth closed and open, flat (coplanar rings), a sheet-metal profile
  // with 90 and 30 degree folds both ways, and crumpled balls full of sharp
  // concave and convex vertices.
  const Tally sphere = ExpectSoundProofs(testing::Icosphere(20, 2), 1);
  EXPECT_GT(sphere.proofs, 2000);
  const Tally torus = ExpectSoundProofs(testing::Torus(30, 10, 36, 18), 2);
  EXPECT_GT(torus.proofs, 4000);
  const Tally flat = ExpectSoundProofs(
      testing::HeightField(0, 10, 0, 10, 11, 11, [](double, double) { return 0.0; }), 3);
  EXPECT_GT(flat.proofs, 1000);
  const Tally waves = ExpectSoundProofs(
      testing::HeightField(
          0, 20, 0, 20, 15, 15,
          [](double x, double y) { return 2 * std::sin(x / 2) * std::cos(y / 3); }),
      4);
  EXPECT_GT(waves.proofs, 1000);
  TriangleMesh folds;
  const std::vector<Eigen::Vector2d> profile = {{0, 0},    {5, 0},  {5, 5},  {10, 5},
                                                {14, 7.3}, {18, 5}, {25, 5}, {25, 0}};
  for (int j = 0; j < 6; ++j)
    for (const auto& q : profile) folds.vertices.emplace_back(q.x(), 2 * j, q.y());
  const auto np = static_cast<uint32_t>(profile.size());
  for (uint32_t j = 0; j + 1 < 6; ++j)
    for (uint32_t i = 0; i + 1 < np; ++i) {
      const uint32_t a = j * np + i;
      folds.triangles.push_back({a, a + 1, a + np + 1});
      folds.triangles.push_back({a, a + np + 1, a + np});
    }
  EXPECT_GT(ExpectSoundProofs(folds, 5).proofs, 200);
  for (uint64_t seed : {6, 7}) {
    TriangleMesh ball = testing::Icosphere(20, 2);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> scale(0.4f, 1.4f);
    for (auto& v : ball.vertices) v *= scale(rng);
    const Tally crumpled = ExpectSoundProofs(ball, seed);
    EXPECT_GT(crumpled.proofs, 100) << "seed " << seed;
  }
}

// A neighbour at corner A that lies past the end of edge AB and rises at
// 45 degrees: a point high over the face near AB is closer to it than to
// the face, which only the bound along the edge's line (γ) sees; points
// low over the face still get proofs, and every proof holds. Where the
// face's angle at A is obtuse that bound must not be used at all.
TEST(HintAlone, ANeighbourRisingPastAnEdgesEndIsCounted) {
  TriangleMesh m;
  m.vertices = {{0, 0, 0}, {10, 0, 0}, {5, 10, 0}, {-10, -0.1f, 10}, {-10, -2, 10}};
  m.triangles = {{0, 1, 2}, {0, 4, 3}};
  const std::vector<uint32_t> weld = Weld(m);
  const std::vector<uint32_t> ring = Ring(m, weld, 0);
  const Vector3d n = Normal(m, 0);
  const HintRise rise = ComputeHintRise(m, weld, 0, n, ring.data(), ring.size());
  ASSERT_TRUE(rise.valid);
  const Vector3d a[3] = {V(m, 0), V(m, 1), V(m, 2)};
  const Vector3d p(3, 0.5, 10);
  const PointTriangleResult face = ClosestPointOnTriangle(p, a[0], a[1], a[2]);
  ASSERT_EQ(face.feature, ClosestFeature::kFace);
  ASSERT_LT(D2(m, 1, p), face.squared_distance);  // the neighbour is closer
  EXPECT_FALSE(RingIsFarther(rise, p, face.point, std::sqrt(face.squared_distance), n, m, 0));
  EXPECT_GT(ExpectSoundProofs(m, 8).proofs, 3);

  // The face's angle at A is obtuse, so q can project past A as far as the
  // gently rising neighbour reaches: the bound along the line must not
  // apply there.
  m.vertices = {{0, 0, 0}, {10, 0, 0}, {-20, 2, 0}, {-20, -0.1f, 2}, {-20, -3, 2}};
  const HintRise obtuse = ComputeHintRise(m, weld, 0, Normal(m, 0), ring.data(), ring.size());
  ASSERT_TRUE(obtuse.valid);
  const Vector3d a2[3] = {V(m, 0), V(m, 1), V(m, 2)};
  const Vector3d low(-15, 1.6, 3);
  const PointTriangleResult over = ClosestPointOnTriangle(low, a2[0], a2[1], a2[2]);
  ASSERT_EQ(over.feature, ClosestFeature::kFace);
  ASSERT_LT(D2(m, 1, low), over.squared_distance);
  EXPECT_FALSE(
      RingIsFarther(obtuse, low, over.point, std::sqrt(over.squared_distance), Normal(m, 0), m, 0));
  ExpectSoundProofs(m, 9);
}

// Two triangles over the same corners, a neighbour folded back over the
// face, and a sliver: no proof.
TEST(HintAlone, NoProofForDuplicatesFoldsAndSlivers) {
  TriangleMesh m;
  m.vertices = {{0, 0, 0}, {10, 0, 0}, {0, 10, 0}, {8, 8, 0}, {3, 3, 1}, {5, -0.0001f, 0}};
  m.triangles = {{0, 1, 2}, {0, 1, 2}};  // a duplicate
  std::vector<uint32_t> weld = Weld(m);
  std::vector<uint32_t> ring = {0, 1};
  EXPECT_FALSE(ComputeHintRise(m, weld, 0, Normal(m, 0), ring.data(), ring.size()).valid);
  m.triangles = {{0, 1, 2}, {1, 2, 4}};  // the neighbour's corner (3, 3, 1) lies over the face
  weld = Weld(m);
  EXPECT_FALSE(ComputeHintRise(m, weld, 0, Normal(m, 0), ring.data(), ring.size()).valid);
  m.triangles = {{0, 1, 2}, {1, 3, 2}};  // a proper neighbour across BC
  EXPECT_TRUE(ComputeHintRise(m, weld, 0, Normal(m, 0), ring.data(), ring.size()).valid);
  m.triangles = {{0, 1, 5}};  // a sliver
  weld = Weld(m);
  ring = {0};
  EXPECT_FALSE(ComputeHintRise(m, weld, 0, Normal(m, 0), ring.data(), ring.size()).valid);
}

}  // namespace
}  // namespace surfinspect
