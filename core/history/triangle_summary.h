// One part's deviation field per CAD triangle: for each triangle that is the
// closest triangle of some matched point, the count, mean, min and max of
// those points' signed deviations (mm). This is what the store keeps so that
// maps across parts (trend_map.h) need no point clouds.
#pragma once

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "core/history/results_store.h"

namespace surfinspect {

// triangle_id[i] is point i's closest triangle (UINT32_MAX = unmatched) and
// deviation_mm[i] its deviation (NaN = unmatched); both are skipped. Sorted
// by triangle id. Fails on different lengths or an id >= num_triangles.
absl::StatusOr<std::vector<TriangleStat>> SummarizeByTriangle(
    const std::vector<uint32_t>& triangle_id, const std::vector<float>& deviation_mm,
    uint32_t num_triangles);

}  // namespace surfinspect
