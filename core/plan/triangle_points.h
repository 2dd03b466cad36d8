// The error map's matched points grouped by their closest CAD triangle, so
// that a feature touching a few triangles (a section's slab, one
// triangle's coverage) reads their points without a pass over the map.
// Built once per plan evaluation and shared.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "core/errormap/error_map.h"

namespace surfinspect {

struct TrianglePoints {
  // Triangle t's points: indices into the error map's arrays,
  // points[offsets[t] .. offsets[t + 1]), ascending.
  std::vector<uint32_t> offsets;  // number of triangles + 1
  std::vector<uint32_t> points;
  uint32_t begin(std::size_t t) const { return offsets[t]; }
  uint32_t end(std::size_t t) const { return offsets[t + 1]; }
};

// A counting sort, counted and placed in parallel blocks (the caller's
// TBB arena). Unmatched points (triangle id UINT32_MAX) are left out;
// InvalidArgument for another id at or beyond `triangles`, or arrays of
// different sizes.
absl::StatusOr<TrianglePoints> PointsByTriangle(const ErrorMapResult& error_map,
                                                std::size_t triangles);

}  // namespace surfinspect
