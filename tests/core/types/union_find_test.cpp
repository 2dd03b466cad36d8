// core/types/union_find.cpp against breadth-first search on random graphs.
#include "core/types/union_find.h"

#include <gtest/gtest.h>

#include <queue>
#include <random>
#include <utility>
#include <vector>

namespace surfinspect {
namespace {

// Component of every vertex by BFS, numbered by each component's smallest vertex.
std::vector<int32_t> ComponentsByBfs(int n, const std::vector<std::pair<int, int>>& edges) {
  std::vector<std::vector<int>> adj(n);
  for (auto [a, b] : edges) {
    adj[a].push_back(b);
    adj[b].push_back(a);
  }
  std::vector<int32_t> comp(n, -1);
  for (int s = 0; s < n; ++s) {
    if (comp[s] >= 0) continue;
    std::queue<int> q;
    q.push(s);
    comp[s] = s;
    while (!q.empty()) {
      const int u = q.front();
      q.pop();
      for (int v : adj[u])
        if (comp[v] < 0) {
          comp[v] = s;
          q.push(v);
        }
    }
  }
  return comp;
}

TEST(UnionFind, MatchesBreadthFirstSearchOnRandomGraphs) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 1 + static_cast<int>(rng() % 300);
    const int m = static_cast<int>(rng() % (2 * n));
    std::vector<std::pair<int, int>> edges;
    for (int e = 0; e < m; ++e)
      edges.emplace_back(static_cast<int>(rng() % n), static_cast<int>(rng() % n));
    UnionFind uf(n);
    for (auto [a, b] : edges) uf.Union(a, b);
    const std::vector<int32_t> bfs = ComponentsByBfs(n, edges);
    // The root is the smallest index of its set, exactly the BFS numbering.
    for (int i = 0; i < n; ++i) ASSERT_EQ(uf.Find(i), bfs[i]) << "trial " << trial << " i " << i;
  }
}

TEST(UnionFind, ParentNeverExceedsIndex) {
  std::mt19937 rng(11);
  UnionFind uf;
  for (int i = 0; i < 500; ++i) {
    const int32_t id = uf.Add();
    ASSERT_EQ(id, i);
    if (i > 0) uf.Union(id, static_cast<int32_t>(rng() % i));
    if (i > 1) uf.Union(static_cast<int32_t>(rng() % i), static_cast<int32_t>(rng() % i));
  }
  const std::vector<int32_t> parent = std::move(uf).ReleaseParents();
  ASSERT_EQ(parent.size(), 500u);
  for (std::size_t i = 0; i < parent.size(); ++i) EXPECT_LE(parent[i], static_cast<int32_t>(i));
}

TEST(UnionFind, LinkRootsReturnsTheSmallerRoot) {
  UnionFind uf(4);
  EXPECT_EQ(uf.LinkRoots(3, 1), 1);
  EXPECT_EQ(uf.Find(3), 1);
  EXPECT_EQ(uf.Union(0, 3), 0);
  EXPECT_EQ(uf.Find(1), 0);
  EXPECT_EQ(uf.Find(2), 2);
  EXPECT_EQ(uf.Union(2, 2), 2);
}

// Forests built apart and appended, then joined by unions across them,
// give the sets (and roots) of one forest built with all the unions.
TEST(UnionFind, AppendedForestsJoinAsOne) {
  std::mt19937 rng(12);
  const int sizes[3] = {40, 1, 25};
  UnionFind whole(66), joined;
  int offset = 0;
  for (int n : sizes) {
    UnionFind part(static_cast<std::size_t>(n));
    for (int k = 0; k < n / 2; ++k) {
      const auto a = static_cast<int32_t>(rng() % n), b = static_cast<int32_t>(rng() % n);
      part.Union(a, b);
      whole.Union(a + offset, b + offset);
    }
    joined.Append(part);
    offset += n;
  }
  ASSERT_EQ(joined.size(), 66u);
  for (int k = 0; k < 10; ++k) {
    const auto a = static_cast<int32_t>(rng() % 66), b = static_cast<int32_t>(rng() % 66);
    whole.Union(a, b);
    joined.Union(a, b);
  }
  for (int32_t i = 0; i < 66; ++i) ASSERT_EQ(joined.Find(i), whole.Find(i)) << i;
}

}  // namespace
}  // namespace surfinspect
