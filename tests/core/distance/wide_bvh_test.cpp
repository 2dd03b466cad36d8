// Covers core/distance/wide_bvh.cpp (the copy of Embree's tree into our
// layout) and core/distance/wide_bvh_search.cpp (the search of each
// instruction set): the tree's invariants, and the search against brute
// force through a plain callback. mesh_index_test.cpp checks the answers of
// whole indices; prism_bound_test.cpp checks the leaf bound.
#include "core/distance/wide_bvh.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstring>
#include <limits>
#include <random>

#include "core/distance/embree_handles.h"
#include "core/distance/point_triangle.h"

namespace surfinspect {
namespace {

using Eigen::Vector3d;
using Eigen::Vector3f;

TriangleMesh Soup(int n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> centre(0, 100), size(-5, 5);
  TriangleMesh m;
  for (int i = 0; i < n; ++i) {
    const Vector3f c(centre(rng), centre(rng), centre(rng));
    for (int k = 0; k < 3; ++k) m.vertices.push_back(c + Vector3f(size(rng), size(rng), size(rng)));
    const auto b = static_cast<uint32_t>(3 * i);
    m.triangles.push_back({b, b + 1, b + 2});
  }
  return m;
}

std::vector<Vector3d> Normals(const TriangleMesh& m) {
  std::vector<Vector3d> n;
  for (const auto& t : m.triangles) {
    const Vector3d a = m.vertices[t[0]].cast<double>(), b = m.vertices[t[1]].cast<double>(),
                   c = m.vertices[t[2]].cast<double>();
    n.push_back((b - a).cross(c - a).normalized());
  }
  return n;
}

std::vector<TriangleShape> Shapes(const TriangleMesh& m) {
  std::vector<TriangleShape> s;
  for (const auto& t : m.triangles)
    s.push_back(ClassifyTriangle(m.vertices[t[0]].cast<double>(), m.vertices[t[1]].cast<double>(),
                                 m.vertices[t[2]].cast<double>()));
  return s;
}

WideBvh BuildOrDie(const TriangleMesh& m, RTCBuildQuality quality, SearchIsa isa) {
  auto device = EmbreeDevice::Create();
  EXPECT_TRUE(device.ok());
  auto bvh = WideBvh::Build((*device)->get(), m, Normals(m), Shapes(m), quality, isa);
  EXPECT_TRUE(bvh.ok()) << bvh.status();
  return *std::move(bvh);
}

// Walks the tree: every triangle sits in exactly one leaf lane, with its
// own vertices; every child box holds its subtree's vertices; depth and
// node counts agree with the stats; each leaf lies in one block.
void CheckSubtree(const wide::View& v, const TriangleMesh& m, uint32_t node, int depth,
                  std::vector<int>& seen, int& max_depth, std::size_t& leaves) {
  max_depth = std::max(max_depth, depth);
  const wide::Node& n = v.nodes[node];
  ASSERT_GE(n.count, 1u);
  ASSERT_LE(n.count, static_cast<uint32_t>(wide::kWidth));
  for (uint32_t i = 0; i < n.count; ++i) {
    auto inside = [&](const Vector3f& p) {
      for (int a = 0; a < 3; ++a)
        if (p[a] < n.lo[a][i] || p[a] > n.hi[a][i]) return false;
      return true;
    };
    if (n.leaf_triangles[i] == 0) {
      CheckSubtree(v, m, n.child[i], depth + 1, seen, max_depth, leaves);
      continue;
    }
    ASSERT_LE(n.leaf_triangles[i], wide::kMaxLeafTriangles);
    ++leaves;
    ASSERT_EQ(n.child[i] / wide::kLeafWidth,
              (n.child[i] + n.leaf_triangles[i] - 1) / wide::kLeafWidth)
        << "a leaf spans two blocks";
    for (uint32_t j = n.child[i]; j < n.child[i] + n.leaf_triangles[i]; ++j) {
      const wide::LeafBlock& block = v.blocks[j / wide::kLeafWidth];
      const int lane = static_cast<int>(j % wide::kLeafWidth);
      const uint32_t t = block.triangle[lane];
      ASSERT_LT(t, m.num_triangles());
      ++seen[t];
      for (int k = 0; k < 3; ++k) {
        const Vector3f& p = m.vertices[m.triangles[t][k]];
        EXPECT_TRUE(inside(p)) << "triangle " << t << " outside its leaf box";
        for (int a = 0; a < 3; ++a) EXPECT_EQ(block.vertex[k][a][lane], p[a]);
      }
      const auto& tri = m.triangles[t];
      EXPECT_EQ(block.shape[lane],
                static_cast<uint8_t>(ClassifyTriangle(m.vertices[tri[0]].cast<double>(),
                                                      m.vertices[tri[1]].cast<double>(),
                                                      m.vertices[tri[2]].cast<double>())));
    }
  }
}

TEST(WideBvh, EveryTriangleIsInOneLeafInsideEveryBoxAboveIt) {
  for (RTCBuildQuality q : {RTC_BUILD_QUALITY_LOW, RTC_BUILD_QUALITY_HIGH})
    for (int n : {1, 3, 5, 2000}) {
      const TriangleMesh m = Soup(n, 7);
      const WideBvh bvh = BuildOrDie(m, q, SearchIsa::kSse2);
      std::vector<int> seen(m.num_triangles(), 0);
      int depth = 0;
      std::size_t leaves = 0;
      CheckSubtree(bvh.view(), m, 0, 1, seen, depth, leaves);
      for (int s : seen) ASSERT_EQ(s, 1);
      // No block more than needed: at most one per leaf, and full blocks
      // but for the lanes a leaf that did not fit left empty.
      EXPECT_GE(bvh.stats().leaf_blocks,
                (m.num_triangles() + wide::kLeafWidth - 1) / wide::kLeafWidth);
      EXPECT_LE(bvh.stats().leaf_blocks, leaves);
      EXPECT_EQ(depth, bvh.stats().depth);
      EXPECT_LE(depth, wide::kMaxDepth);
      EXPECT_GT(bvh.memory_bytes(), 0u);
    }
}

// A plain callback that records every offered triangle and keeps the
// minimum, as the mesh index does, with no search radius beyond it.
struct Recorder {
  const TriangleMesh* mesh;
  Vector3d p;
  uint32_t best = UINT32_MAX;
  int offers = 0;
};

bool Record(wide::Query& q, const wide::LeafBlock& block, int lane) {
  auto& r = *static_cast<Recorder*>(q.context);
  ++r.offers;
  const uint32_t t = block.triangle[lane];
  const auto& tri = r.mesh->triangles[t];
  const double d2 = ClosestPointOnTriangle(r.p, r.mesh->vertices[tri[0]].cast<double>(),
                                           r.mesh->vertices[tri[1]].cast<double>(),
                                           r.mesh->vertices[tri[2]].cast<double>())
                        .squared_distance;
  if (!(d2 < q.best_d2 || (d2 == q.best_d2 && t < r.best))) return false;
  q.best_d2 = d2;
  r.best = t;
  // The mesh index's padding: 1e-6 relative + 1e-6 of the coordinates.
  const double radius = std::sqrt(d2) * (1 + 1e-6) + 1e-6 * r.p.cwiseAbs().maxCoeff() + 1e-9;
  q.box_radius2 = std::nextafter(static_cast<float>(radius * radius), INFINITY);
  return true;
}

TEST(WideBvh, SearchFindsTheBruteForceMinimiserInEveryIsaAndPrunes) {
  const TriangleMesh m = Soup(3000, 9);
  std::mt19937_64 rng(10);
  std::uniform_real_distribution<double> u(-20, 120);
  for (SearchIsa isa : {SearchIsa::kSse2, SearchIsa::kAvx2}) {
    if (!SearchIsaSupported(isa)) continue;
    const WideBvh bvh = BuildOrDie(m, RTC_BUILD_QUALITY_HIGH, isa);
    EXPECT_EQ(bvh.isa(), isa);
    int offers = 0;
    for (int i = 0; i < 300; ++i) {
      Recorder r{&m, Vector3d(u(rng), u(rng), u(rng))};
      wide::Query q{
          {r.p.x(), r.p.y(), r.p.z()},
          {static_cast<float>(r.p.x()), static_cast<float>(r.p.y()), static_cast<float>(r.p.z())},
          INFINITY,
          INFINITY,
          LeafMargin(r.p),
          &r,
          &Record};
      bvh.Search(q);
      uint32_t want = UINT32_MAX;
      double want_d2 = INFINITY;
      for (uint32_t t = 0; t < m.num_triangles(); ++t) {
        const auto& tri = m.triangles[t];
        const double d2 = ClosestPointOnTriangle(r.p, m.vertices[tri[0]].cast<double>(),
                                                 m.vertices[tri[1]].cast<double>(),
                                                 m.vertices[tri[2]].cast<double>())
                              .squared_distance;
        if (d2 < want_d2) want_d2 = d2, want = t;
      }
      ASSERT_EQ(r.best, want) << SearchIsaName(isa) << " point " << i;
      EXPECT_EQ(q.best_d2, want_d2);
      offers += r.offers;
    }
    // It culls: far fewer kernel calls than triangles.
    EXPECT_LT(offers, 300 * 60) << SearchIsaName(isa);
  }
}

// NextUp is std::nextafter(f, INFINITY), bit for bit, on the edge cases
// and on random floats of every magnitude and sign.
TEST(WideBvh, NextUpIsNextafterTowardsInfinity) {
  std::vector<float> values = {0.f,
                               -0.f,
                               std::numeric_limits<float>::denorm_min(),
                               std::numeric_limits<float>::min(),
                               1.f,
                               std::numeric_limits<float>::max(),
                               INFINITY,
                               -INFINITY,
                               -1.f,
                               -std::numeric_limits<float>::max(),
                               NAN};
  std::mt19937 rng(5);
  for (int i = 0; i < 100000; ++i) {
    const uint32_t bits = static_cast<uint32_t>(rng());
    float f;
    std::memcpy(&f, &bits, sizeof f);
    values.push_back(f);
  }
  for (float f : values) {
    const float want = std::nextafter(f, INFINITY), got = NextUp(f);
    if (std::isnan(want)) {
      EXPECT_TRUE(std::isnan(got));
      continue;
    }
    uint32_t a, b;
    std::memcpy(&a, &want, sizeof a);
    std::memcpy(&b, &got, sizeof b);
    ASSERT_EQ(a, b) << f;
  }
  // float(0.1) lies above 0.1, float(0.7) below 0.7.
  EXPECT_EQ(RoundUpToFloat(0.1), static_cast<float>(0.1));
  EXPECT_EQ(RoundUpToFloat(0.7), std::nextafter(static_cast<float>(0.7), INFINITY));
  EXPECT_GE(static_cast<double>(RoundUpToFloat(0.7)), 0.7);
  EXPECT_EQ(RoundUpToFloat(0.5), 0.5f);
}

}  // namespace
}  // namespace surfinspect
