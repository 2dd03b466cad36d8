#include "server/memory_budget.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <thread>
#include <vector>

#include "core/distance/mesh_index.h"
#include "core/simulation/demo_cell.h"

namespace surfinspect::server {
namespace {

TEST(MemoryBudget, ReservesUpToTheBudgetAndReleasesOnDestruction) {
  MemoryBudget budget(1000);
  {
    auto a = budget.TryReserve(600, "call a");
    ASSERT_TRUE(a.ok()) << a.status();
    EXPECT_EQ(budget.reserved_bytes(), 600u);
    auto b = budget.TryReserve(400, "call b");
    ASSERT_TRUE(b.ok()) << b.status();
    EXPECT_EQ(budget.reserved_bytes(), 1000u);
    auto c = budget.TryReserve(1, "call c");
    ASSERT_EQ(c.status().code(), absl::StatusCode::kResourceExhausted);
    EXPECT_NE(c.status().message().find("call c"), std::string::npos);
    EXPECT_NE(c.status().message().find("retry later"), std::string::npos);
    EXPECT_EQ(budget.refused_bytes(), 1u);
  }
  EXPECT_EQ(budget.reserved_bytes(), 0u);
}

TEST(MemoryBudget, ARequestLargerThanTheWholeBudgetSaysItNeverFits) {
  MemoryBudget budget(1 << 20);
  auto r = budget.TryReserve(uint64_t{3} << 20, "Inspect part p1");
  ASSERT_EQ(r.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_NE(r.status().message().find("more than the server's whole memory budget"),
            std::string::npos)
      << r.status();
  EXPECT_EQ(budget.reserved_bytes(), 0u);
}

TEST(MemoryBudget, MovedReservationsReleaseOnce) {
  MemoryBudget budget(100);
  auto a = budget.TryReserve(70, "a");
  ASSERT_TRUE(a.ok());
  MemoryBudget::Reservation held = std::move(*a);
  MemoryBudget::Reservation other;
  other = std::move(held);
  EXPECT_EQ(budget.reserved_bytes(), 70u);
  other.Release();
  other.Release();
  EXPECT_EQ(budget.reserved_bytes(), 0u);
}

TEST(MemoryBudget, ConcurrentCallsNeverPassTheBudget) {
  MemoryBudget budget(10'000);
  std::atomic<uint64_t> worst{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 8; ++t)
    threads.emplace_back([&, t] {
      for (int i = 0; i < 20'000; ++i) {
        auto r = budget.TryReserve(1000 + 37 * ((i + t) % 50), "x");
        const uint64_t now = budget.reserved_bytes();
        uint64_t seen = worst.load();
        while (now > seen && !worst.compare_exchange_weak(seen, now)) {
        }
      }
    });
  for (auto& th : threads) th.join();
  EXPECT_LE(worst.load(), 10'000u);
  EXPECT_EQ(budget.reserved_bytes(), 0u);
}

TEST(MemoryBudget, DefaultBudgetFollowsTheTightestLimit) {
  const MemoryLimits m = DetectMemoryLimits();
  ASSERT_GT(m.physical_bytes, 0u);
  EXPECT_LE(m.default_budget_bytes, m.physical_bytes / 4 * 3);
  if (m.cgroup_bytes != 0) {
    EXPECT_LE(m.default_budget_bytes, m.cgroup_bytes / 4 * 3);
  }
  if (m.address_space_bytes != 0) {
    EXPECT_LE(m.default_budget_bytes, m.address_space_bytes / 2);
  }
  EXPECT_GT(m.default_budget_bytes, 0u);
  EXPECT_FALSE(m.source.empty());
}

// The reservation for building an inline mesh's index covers the finished
// index (mesh, normals, Embree's BVH) twice over, for the build's transient
// memory: measured on the demo part and on a fine torus.
TEST(MemoryBudget, TheMeshIndexReservationCoversTheIndexTwice) {
  for (const TriangleMesh& mesh : {MakeDemoCell().part, MakeDemoCell().gauge}) {
    auto index = MeshIndex::Build(mesh);
    ASSERT_TRUE(index.ok());
    const double per_triangle =
        static_cast<double>((*index)->memory_bytes()) / static_cast<double>(mesh.num_triangles());
    std::printf("index: %zu triangles, %.1f B per triangle\n", mesh.num_triangles(), per_triangle);
    EXPECT_LE(2 * per_triangle, static_cast<double>(MeshIndexBytesPerTriangle()));
  }
}

}  // namespace
}  // namespace surfinspect::server
