#include "core/history/trend_map.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace surfinspect {

TrendMap ComputeTrendMap(const std::vector<PartRecord>& parts) {
  TrendMap map;
  // Welford's running mean and sum of squares (Knuth, TAOCP vol. 2, 4.2.2).
  struct Acc {
    uint32_t n = 0;
    double mean = 0, m2 = 0;
  };
  std::map<uint32_t, Acc> acc;
  for (const PartRecord& p : parts) {
    if (p.triangles.empty()) continue;
    ++map.parts;
    map.num_triangles = std::max(map.num_triangles, p.num_triangles);
    for (const TriangleStat& t : p.triangles) {
      Acc& a = acc[t.triangle_id];
      ++a.n;
      const double delta = t.mean_mm - a.mean;
      a.mean += delta / a.n;
      a.m2 += delta * (t.mean_mm - a.mean);
    }
  }
  // A triangle seen in fewer than half the parts (a rim the sensor mostly
  // misses) does not compete for the largest mean.
  const uint32_t enough = static_cast<uint32_t>(std::max<std::size_t>(1, map.parts / 2));
  double largest = -1;
  for (const auto& [id, a] : acc) {
    map.triangles.push_back({id, a.n, a.mean, a.n > 1 ? std::sqrt(a.m2 / (a.n - 1)) : NAN});
    if (a.n >= enough && std::abs(a.mean) > largest) {
      largest = std::abs(a.mean);
      map.largest = static_cast<int>(map.triangles.size()) - 1;
    }
  }
  return map;
}

}  // namespace surfinspect
