// The process trend map: per CAD triangle, the mean and the standard
// deviation over parts of the triangle's per-part mean deviation (mm). A
// systematic error (a die that pushes the ridge up) has a large mean and a
// small sigma; random error has a mean near 0.
#pragma once

#include <cstdint>
#include <vector>

#include "core/history/results_store.h"

namespace surfinspect {

struct TriangleTrend {
  uint32_t triangle_id = 0;
  uint32_t parts = 0;     // parts with points on this triangle
  double mean_mm = 0;     // mean over those parts of the per-part mean
  double sigma_mm = NAN;  // sample standard deviation of the same (NaN with one part)
};

struct TrendMap {
  uint32_t num_triangles = 0;            // the mesh's, from the parts' summaries
  std::size_t parts = 0;                 // parts with a triangle summary
  std::vector<TriangleTrend> triangles;  // triangles with points, by id
  // The triangle with the largest |mean| among those seen in at least half
  // the parts (index into `triangles`, -1 if none).
  int largest = -1;
};

TrendMap ComputeTrendMap(const std::vector<PartRecord>& parts);

}  // namespace surfinspect
