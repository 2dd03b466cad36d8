#include "core/plan/triangle_points.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <utility>

namespace surfinspect {

absl::StatusOr<TrianglePoints> PointsByTriangle(const ErrorMapResult& em, std::size_t triangles) {
  const std::vector<uint32_t>& id = em.triangle_id;
  const std::size_t n = id.size(), block = std::size_t{1} << 18;
  if (em.closest_point.size() != n || em.deviation_mm.size() != n)
    return absl::InvalidArgumentError("error map arrays differ in size");
  if (n >= UINT32_MAX) return absl::InvalidArgumentError("error map too large to index");
  const std::size_t blocks = (n + block - 1) / block;
  // count[b][t]: block b's points on triangle t; then where they go.
  std::vector<std::vector<uint32_t>> count(blocks, std::vector<uint32_t>(triangles, 0));
  std::vector<char> bad(blocks, 0);
  tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
    for (std::size_t i = b * block; i < std::min(n, (b + 1) * block); ++i) {
      if (id[i] < triangles)
        ++count[b][id[i]];
      else
        bad[b] |= id[i] != UINT32_MAX;
    }
  });
  if (std::find(bad.begin(), bad.end(), 1) != bad.end())
    return absl::InvalidArgumentError("error map: triangle id beyond the part mesh");
  TrianglePoints out;
  out.offsets.assign(triangles + 1, 0);
  uint32_t next = 0;
  for (std::size_t t = 0; t < triangles; ++t) {
    out.offsets[t] = next;
    for (std::size_t b = 0; b < blocks; ++b) {
      const uint32_t c = count[b][t];
      count[b][t] = next;
      next += c;
    }
  }
  out.offsets[triangles] = next;
  out.points.resize(next);
  tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
    for (std::size_t i = b * block; i < std::min(n, (b + 1) * block); ++i)
      if (id[i] < triangles) out.points[count[b][id[i]]++] = static_cast<uint32_t>(i);
  });
  return out;
}

}  // namespace surfinspect
