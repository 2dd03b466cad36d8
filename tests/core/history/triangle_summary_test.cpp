// Per-triangle summaries and the trend map across parts, against brute force.
// Also covers core/history/trend_map.cpp.
#include "core/history/triangle_summary.h"

#include <gtest/gtest.h>

#include <random>

#include "core/history/trend_map.h"

namespace surfinspect {
namespace {

TEST(TriangleSummary, EqualsBruteForce) {
  std::mt19937_64 rng(1);
  std::uniform_int_distribution<uint32_t> tri(0, 19);
  std::normal_distribution<float> dev(0.01f, 0.02f);
  std::vector<uint32_t> ids(5000);
  std::vector<float> d(5000);
  for (std::size_t i = 0; i < ids.size(); ++i) {
    ids[i] = i % 97 == 0 ? UINT32_MAX : tri(rng);
    d[i] = i % 89 == 0 ? NAN : dev(rng);
  }
  auto s = SummarizeByTriangle(ids, d, 25);
  ASSERT_TRUE(s.ok());
  ASSERT_EQ(s->size(), 20u);  // triangles 20..24 have no points
  for (const TriangleStat& t : *s) {
    double sum = 0, lo = INFINITY, hi = -INFINITY;
    uint32_t n = 0;
    for (std::size_t i = 0; i < ids.size(); ++i)
      if (ids[i] == t.triangle_id && std::isfinite(d[i]))
        sum += d[i], ++n, lo = std::min<double>(lo, d[i]), hi = std::max<double>(hi, d[i]);
    EXPECT_EQ(t.count, n);
    EXPECT_NEAR(t.mean_mm, sum / n, 1e-6);
    EXPECT_EQ(t.min_mm, lo);
    EXPECT_EQ(t.max_mm, hi);
  }
}

TEST(TriangleSummary, RefusesMismatchAndOutOfRangeIds) {
  EXPECT_FALSE(SummarizeByTriangle({1, 2}, {0.f}, 5).ok());
  const auto st = SummarizeByTriangle({7}, {0.f}, 5).status();
  EXPECT_NE(st.message().find("triangle id 7"), std::string::npos) << st;
}

TEST(TrendMap, MeanAndSigmaOverPartsEqualBruteForce) {
  std::mt19937_64 rng(2);
  std::normal_distribution<float> dev(0, 0.01f);
  std::vector<PartRecord> parts(12);
  for (std::size_t p = 0; p < parts.size(); ++p) {
    parts[p].num_triangles = 10;
    for (uint32_t t = 0; t < 10; ++t)
      if ((t + p) % 4 != 0)  // not every part sees every triangle
        parts[p].triangles.push_back({t, 5, (t == 6 ? 0.05f : 0.f) + dev(rng), 0, 0});
  }
  const TrendMap map = ComputeTrendMap(parts);
  EXPECT_EQ(map.parts, 12u);
  ASSERT_EQ(map.triangles.size(), 10u);
  for (const TriangleTrend& tt : map.triangles) {
    std::vector<double> means;
    for (const PartRecord& p : parts)
      for (const TriangleStat& s : p.triangles)
        if (s.triangle_id == tt.triangle_id) means.push_back(s.mean_mm);
    double m = 0, ss = 0;
    for (double v : means) m += v;
    m /= means.size();
    for (double v : means) ss += (v - m) * (v - m);
    EXPECT_EQ(tt.parts, means.size());
    EXPECT_NEAR(tt.mean_mm, m, 1e-9);
    EXPECT_NEAR(tt.sigma_mm, std::sqrt(ss / (means.size() - 1)), 1e-9);
  }
  ASSERT_GE(map.largest, 0);
  EXPECT_EQ(map.triangles[map.largest].triangle_id, 6u);
}

}  // namespace
}  // namespace surfinspect
