#include "tests/support/link_grids.h"

#include <cmath>
#include <queue>

#include "core/filter/link_clustering.h"

namespace surfinspect::testing {
namespace {
constexpr int32_t kInvalid = LinkClusteringResult::kInvalid;
}  // namespace

PointCloud RandomGrid(std::mt19937& rng, uint32_t w, uint32_t h, double hole_fraction) {
  PointCloud c = PointCloud::Organized(w, h);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (uint32_t r = 0; r < h; ++r)
    for (uint32_t col = 0; col < w; ++col) {
      if (u(rng) < hole_fraction) {
        // No data comes in several spellings; all must count as no data.
        const float nan = NAN;
        const int kind = static_cast<int>(u(rng) * 3);
        c.points[r * w + col] = kind == 0   ? Eigen::Vector3f(nan, nan, nan)
                                : kind == 1 ? Eigen::Vector3f(0.3f * col, nan, 1.f)
                                            : Eigen::Vector3f(0.3f * col, 0.3f * r, -nan);
        continue;
      }
      c.points[r * w + col] = {0.3f * col, 0.3f * r, 0.6f * u(rng)};
    }
  return c;
}

std::vector<int32_t> GridOracle(const PointCloud& c, int connectivity, float r2) {
  const int w = static_cast<int>(c.width), h = static_cast<int>(c.height);
  std::vector<int32_t> label(c.size(), kInvalid);
  int32_t next = 0;
  for (int start = 0; start < w * h; ++start) {
    if (!PointCloud::IsValid(c.points[start]) || label[start] != kInvalid) continue;
    std::queue<int> q;
    q.push(start);
    label[start] = next;
    while (!q.empty()) {
      const int i = q.front();
      q.pop();
      const int r = i / w, col = i % w;
      for (int dr = -1; dr <= 1; ++dr)
        for (int dc = -1; dc <= 1; ++dc) {
          if ((dr == 0 && dc == 0) || (connectivity == 4 && dr != 0 && dc != 0)) continue;
          const int rr = r + dr, cc = col + dc;
          if (rr < 0 || rr >= h || cc < 0 || cc >= w) continue;
          const int j = rr * w + cc;
          if (label[j] != kInvalid || !PointCloud::IsValid(c.points[j])) continue;
          if (!PointsLinked(c.points[i], c.points[j], r2)) continue;
          label[j] = next;
          q.push(j);
        }
    }
    ++next;
  }
  return label;
}

}  // namespace surfinspect::testing
