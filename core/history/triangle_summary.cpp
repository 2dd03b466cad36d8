#include "core/history/triangle_summary.h"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace surfinspect {

absl::StatusOr<std::vector<TriangleStat>> SummarizeByTriangle(
    const std::vector<uint32_t>& triangle_id, const std::vector<float>& deviation_mm,
    uint32_t num_triangles) {
  if (triangle_id.size() != deviation_mm.size())
    return absl::InvalidArgumentError(
        absl::StrCat(triangle_id.size(), " triangle ids but ", deviation_mm.size(), " deviations"));
  struct Acc {
    uint32_t count = 0;
    double sum = 0;
    float min = 0, max = 0;
  };
  std::vector<Acc> acc(num_triangles);
  for (std::size_t i = 0; i < triangle_id.size(); ++i) {
    const uint32_t t = triangle_id[i];
    const float d = deviation_mm[i];
    if (t == UINT32_MAX || !std::isfinite(d)) continue;
    if (t >= num_triangles)
      return absl::InvalidArgumentError(
          absl::StrCat("triangle id ", t, " of point ", i, " is not below ", num_triangles));
    Acc& a = acc[t];
    a.min = a.count == 0 ? d : std::min(a.min, d);
    a.max = a.count == 0 ? d : std::max(a.max, d);
    a.sum += d;
    ++a.count;
  }
  std::vector<TriangleStat> out;
  for (uint32_t t = 0; t < num_triangles; ++t)
    if (acc[t].count > 0)
      out.push_back(
          {t, acc[t].count, static_cast<float>(acc[t].sum / acc[t].count), acc[t].min, acc[t].max});
  return out;
}

}  // namespace surfinspect
