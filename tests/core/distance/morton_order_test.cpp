// core/distance/morton_order.cpp against an oracle (bit-by-bit interleaved
// codes over ComputeBounds, std::stable_sort), and its AVX-512 kernels
// (core/distance/morton_order_avx512.cpp) against its scalar loops.
#include "core/distance/morton_order.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace surfinspect {
namespace {

// Random points in a box, with invalid points (all NaN, or one coordinate
// NaN), repeats, signed zeros and points on the bounds.
PointCloud Cloud(std::size_t n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(-80.f, 120.f);
  std::uniform_int_distribution<int> kind(0, 19);
  std::vector<Eigen::Vector3f> pts(n);
  for (std::size_t i = 0; i < n; ++i) {
    pts[i] = {u(rng), u(rng), 0.25f * u(rng)};
    switch (kind(rng)) {
      case 0:
        pts[i] = Eigen::Vector3f::Constant(NAN);
        break;
      case 1:
        pts[i][static_cast<int>(i % 3)] = NAN;
        break;
      case 2:
        if (i > 0) pts[i] = pts[i - 1];
        break;
      case 3:
        pts[i].x() = (i % 2 ? -0.f : 0.f);
        break;
      default:
        break;
    }
  }
  return PointCloud::Unorganized(std::move(pts));
}

uint64_t InterleavedCode(const uint64_t q[3]) {
  uint64_t code = 0;
  for (int bit = 0; bit < 10; ++bit)
    for (int a = 0; a < 3; ++a) code |= ((q[a] >> bit) & 1u) << (3 * bit + a);
  return code;
}

std::vector<uint64_t> Oracle(const PointCloud& cloud) {
  const Bounds3 b = ComputeBounds(cloud);
  const double extent = b.empty() ? 0.0 : (b.max - b.min).maxCoeff();
  const double scale = extent > 0 ? 1023.0 / extent : 0.0;
  std::vector<uint64_t> items(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    uint64_t code = uint64_t{1} << 30;
    if (PointCloud::IsValid(cloud.points[i])) {
      uint64_t q[3];
      for (int a = 0; a < 3; ++a)
        q[a] =
            static_cast<uint64_t>(std::clamp((cloud.points[i][a] - b.min[a]) * scale, 0.0, 1023.0));
      code = InterleavedCode(q);
    }
    items[i] = code << 32 | i;
  }
  std::stable_sort(items.begin(), items.end(),
                   [](uint64_t x, uint64_t y) { return x >> 32 < y >> 32; });
  return items;
}

std::vector<uint64_t> Order(const PointCloud& cloud, MortonIsa isa, int threads) {
  tbb::task_arena arena(threads);
  DefaultInitVector<uint64_t> items;
  arena.execute([&] { items = MortonOrder(cloud, nullptr, isa); });
  return std::vector<uint64_t>(items.begin(), items.end());
}

// Sizes around the 16-point groups and the 2^16-point blocks.
const std::size_t kSizes[] = {0, 1, 15, 16, 17, 1000, 70001};

TEST(MortonOrder, ScalarOrderIsTheSortedInterleavedCodes) {
  for (std::size_t n : kSizes) {
    const PointCloud cloud = Cloud(n, n + 1);
    EXPECT_EQ(Order(cloud, MortonIsa::kScalar, 2), Oracle(cloud)) << n << " points";
  }
}

// The AVX-512 kernels (where the CPU has them) give the scalar order, item
// for item, on any number of threads, also for a cloud without valid points,
// one of a single repeated point (no extent) and one of extreme floats.
TEST(MortonOrder, EachIsaAndThreadCountGivesTheSameOrder) {
  if (!MortonIsaSupported(MortonIsa::kAvx512)) GTEST_SKIP() << "this CPU has no AVX-512 F+DQ";
  std::vector<PointCloud> clouds;
  for (std::size_t n : kSizes) clouds.push_back(Cloud(n, 7 * n + 3));
  clouds.push_back(
      PointCloud::Unorganized(std::vector<Eigen::Vector3f>(40, Eigen::Vector3f::Constant(NAN))));
  clouds.push_back(
      PointCloud::Unorganized(std::vector<Eigen::Vector3f>(40, Eigen::Vector3f(1, 2, 3))));
  std::vector<Eigen::Vector3f> extreme(48, Eigen::Vector3f(3e38f, -3e38f, 1e-38f));
  for (std::size_t i = 0; i < extreme.size(); i += 3) extreme[i] = -extreme[i];
  clouds.push_back(PointCloud::Unorganized(std::move(extreme)));
  for (const PointCloud& cloud : clouds) {
    const std::vector<uint64_t> want = Order(cloud, MortonIsa::kScalar, 1);
    EXPECT_EQ(Order(cloud, MortonIsa::kAvx512, 1), want) << cloud.size() << " points";
    EXPECT_EQ(Order(cloud, MortonIsa::kAvx512, 2), want) << cloud.size() << " points";
  }
}

}  // namespace
}  // namespace surfinspect
