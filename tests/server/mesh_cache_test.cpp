#include "server/mesh_cache.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "core/distance/mesh_index.h"
#include "tests/support/test_meshes.h"

namespace surfinspect::server {
namespace {

// An axis-aligned cube [0, size]^3 mm (12 triangles).
TriangleMesh Cube(double size) {
  return testing::Box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(size));
}

// Null (and a failed expectation) if the build fails.
std::shared_ptr<const MeshIndex> Index(const TriangleMesh& mesh) {
  MeshIndexSettings settings;
  settings.build_threads = 1;
  auto index = MeshIndex::Build(mesh, settings);
  EXPECT_TRUE(index.ok()) << index.status();
  if (!index.ok()) return nullptr;
  return std::shared_ptr<const MeshIndex>(std::move(*index));
}

TEST(MeshCache, FindReturnsTheSharedIndexInsertedUnderTheKey) {
  const auto a = Index(Cube(10));
  ASSERT_NE(a.get(), nullptr);
  ASSERT_GT(a->memory_bytes(), 0u);
  MeshCache cache(std::size_t{1} << 30);
  EXPECT_EQ(cache.Find("a").get(), nullptr);
  cache.Insert("a", a);
  EXPECT_EQ(cache.Find("a").get(), a.get());
  EXPECT_EQ(cache.Find("a").get(), a.get());  // a hit does not consume the entry
  EXPECT_EQ(cache.Find("b").get(), nullptr);
  EXPECT_EQ(cache.entries(), 1u);
  EXPECT_EQ(cache.bytes(), a->memory_bytes());
}

TEST(MeshCache, EvictsTheLeastRecentlyUsedEntryNotTheOldest) {
  const auto a = Index(Cube(10));
  const auto b = Index(Cube(20));
  const auto c = Index(Cube(30));
  ASSERT_TRUE(a && b && c);
  // Room for any two of the three, not for all three.
  MeshCache cache(a->memory_bytes() + b->memory_bytes() + c->memory_bytes() - 1);
  cache.Insert("a", a);
  cache.Insert("b", b);
  ASSERT_EQ(cache.entries(), 2u);
  // The lookup makes "a", the oldest insert, the most recently used.
  ASSERT_EQ(cache.Find("a").get(), a.get());
  cache.Insert("c", c);
  EXPECT_EQ(cache.Find("b").get(), nullptr);
  EXPECT_EQ(cache.Find("a").get(), a.get());
  EXPECT_EQ(cache.Find("c").get(), c.get());
  EXPECT_EQ(cache.entries(), 2u);
  EXPECT_EQ(cache.bytes(), a->memory_bytes() + c->memory_bytes());
}

TEST(MeshCache, EvictsAsManyEntriesAsTheNewOneNeeds) {
  const auto small1 = Index(Cube(10));
  const auto small2 = Index(Cube(20));
  const auto big = Index(testing::Icosphere(10, 3));  // 1280 triangles
  ASSERT_TRUE(small1 && small2 && big);
  const std::size_t smaller = std::min(small1->memory_bytes(), small2->memory_bytes());
  ASSERT_LT(std::max(small1->memory_bytes(), small2->memory_bytes()), big->memory_bytes());
  // Both small ones fit together; the big one fits only alone.
  MeshCache cache(big->memory_bytes() + smaller - 1);
  cache.Insert("small1", small1);
  cache.Insert("small2", small2);
  ASSERT_EQ(cache.entries(), 2u);
  cache.Insert("big", big);
  EXPECT_EQ(cache.Find("small1").get(), nullptr);
  EXPECT_EQ(cache.Find("small2").get(), nullptr);
  EXPECT_EQ(cache.Find("big").get(), big.get());
  EXPECT_EQ(cache.entries(), 1u);
  EXPECT_EQ(cache.bytes(), big->memory_bytes());
}

TEST(MeshCache, AnIndexLargerThanTheWholeBudgetIsNotKeptAndEvictsNothing) {
  const auto small = Index(Cube(10));
  const auto big = Index(testing::Icosphere(10, 3));
  ASSERT_TRUE(small && big);
  ASSERT_LT(small->memory_bytes(), big->memory_bytes());
  MeshCache cache(small->memory_bytes());
  cache.Insert("small", small);
  cache.Insert("big", big);
  EXPECT_EQ(cache.Find("big").get(), nullptr);
  EXPECT_EQ(cache.Find("small").get(), small.get());
  EXPECT_EQ(cache.entries(), 1u);
  EXPECT_EQ(cache.bytes(), small->memory_bytes());
}

TEST(MeshCache, ReinsertingAKeyReplacesItsEntryAndMakesItTheMostRecent) {
  const auto a1 = Index(Cube(10));
  const auto a2 = Index(Cube(10));
  const auto b = Index(Cube(20));
  const auto c = Index(Cube(30));
  ASSERT_TRUE(a1 && a2 && b && c);
  ASSERT_LT(a1->memory_bytes(), a2->memory_bytes() + c->memory_bytes());
  // Room for any two of a2, b and c, not for all three.
  MeshCache cache(a2->memory_bytes() + b->memory_bytes() + c->memory_bytes() - 1);
  cache.Insert("a", a1);
  cache.Insert("b", b);
  cache.Insert("a", a2);
  EXPECT_EQ(cache.entries(), 2u);
  EXPECT_EQ(cache.bytes(), a2->memory_bytes() + b->memory_bytes());  // a1's bytes are gone
  cache.Insert("c", c);  // evicts one: "b", now the least recently used
  EXPECT_EQ(cache.Find("b").get(), nullptr);
  EXPECT_EQ(cache.Find("a").get(), a2.get());
  EXPECT_EQ(cache.Find("c").get(), c.get());
}

TEST(MeshCache, AnEvictedIndexLivesOnWhileACallerHoldsIt) {
  auto a = Index(Cube(10));
  const auto b = Index(Cube(10));
  ASSERT_TRUE(a && b);
  MeshCache cache(std::max(a->memory_bytes(), b->memory_bytes()));  // one entry at a time
  cache.Insert("a", a);
  const std::weak_ptr<const MeshIndex> watch = a;
  std::shared_ptr<const MeshIndex> held = cache.Find("a");  // a running call's reference
  a.reset();
  cache.Insert("b", b);
  ASSERT_EQ(cache.Find("a").get(), nullptr);
  ASSERT_FALSE(watch.expired());
  EXPECT_EQ(held.use_count(), 1);  // the cache let go of it; only the call holds it
  // Still a working index: the cube's top face is 10 mm below (5, 5, 20), on
  // the side its outward normal points to.
  const ClosestPoint p = held->Closest(Eigen::Vector3d(5, 5, 20));
  ASSERT_TRUE(p.matched());
  EXPECT_NEAR(p.distance_mm, 10.0, 1e-9);
  EXPECT_NEAR(p.signed_distance_mm, 10.0, 1e-9);
  held.reset();
  EXPECT_TRUE(watch.expired());  // the last holder freed it
}

TEST(MeshCache, ConcurrentLookupsAndInsertsKeepTheTotalsConsistent) {
  const std::vector<std::string> keys = {"a", "b", "c"};
  std::vector<std::shared_ptr<const MeshIndex>> indices;
  for (double size : {10.0, 20.0, 30.0}) {
    indices.push_back(Index(Cube(size)));
    ASSERT_NE(indices.back().get(), nullptr);
  }
  // Room for two of the three, so inserts keep evicting one another.
  const std::size_t budget = indices[0]->memory_bytes() + indices[1]->memory_bytes();
  MeshCache cache(budget);
  std::atomic<int> wrong{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int i = 0; i < 2000; ++i) {
        const std::size_t k = static_cast<std::size_t>(i * 7 + t) % keys.size();
        if (auto hit = cache.Find(keys[k])) {
          if (hit != indices[k]) ++wrong;
        } else {
          cache.Insert(keys[k], indices[k]);
        }
      }
    });
  for (auto& th : threads) th.join();
  EXPECT_EQ(wrong.load(), 0);
  // The totals are those of what is actually cached.
  std::size_t bytes = 0;
  std::size_t entries = 0;
  for (const std::string& key : keys)
    if (auto hit = cache.Find(key)) {
      bytes += hit->memory_bytes();
      ++entries;
    }
  EXPECT_GE(entries, 1u);
  EXPECT_EQ(cache.entries(), entries);
  EXPECT_EQ(cache.bytes(), bytes);
  EXPECT_LE(cache.bytes(), budget);
}

}  // namespace
}  // namespace surfinspect::server
