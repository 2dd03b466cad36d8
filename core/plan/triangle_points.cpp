#include "core/plan/triangle_points.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <utility>

namespace surfinspect {

namespace {

// Calls f(id, first index, length) for each run of equal ids in
// [begin, end): neighbouring pixels mostly share a triangle, and a run
// counts or places its points at once.
template <typename F>
void ForEachRun(const std::vector<uint32_t>& id, std::size_t begin, std::size_t end, F&& f) {
  for (std::size_t i = begin; i < end;) {
    std::size_t j = i + 1;
    while (j < end && id[j] == id[i]) ++j;
    f(id[i], i, static_cast<uint32_t>(j - i));
    i = j;
  }
}

}  // namespace

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
    ForEachRun(id, b * block, std::min(n, (b + 1) * block),
               [&](uint32_t t, std::size_t, uint32_t run) {
                 if (t < triangles)
                   count[b][t] += run;
                 else
                   bad[b] |= t != UINT32_MAX;
               });
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
    ForEachRun(id, b * block, std::min(n, (b + 1) * block),
               [&](uint32_t t, std::size_t first, uint32_t run) {
                 if (t >= triangles) return;
                 uint32_t* to = out.points.data() + count[b][t];
                 for (uint32_t k = 0; k < run; ++k) to[k] = static_cast<uint32_t>(first + k);
                 count[b][t] += run;
               });
  });
  return out;
}

}  // namespace surfinspect
