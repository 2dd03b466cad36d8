// A finely tessellated wavy sheet (z = 3 sin(x/20) cos(y/25) mm) for the
// ray-casting benchmarks: `cells` x `cells` quads over size_mm x size_mm.
#pragma once

#include <cmath>

#include "core/types/triangle_mesh.h"

namespace surfinspect::bench {

inline TriangleMesh WavySheet(int cells, double size_mm) {
  TriangleMesh m;
  for (int j = 0; j <= cells; ++j)
    for (int i = 0; i <= cells; ++i) {
      const double x = size_mm * (double(i) / cells - 0.5), y = size_mm * (double(j) / cells - 0.5);
      m.vertices.emplace_back(x, y, 3.0 * std::sin(x / 20.0) * std::cos(y / 25.0));
    }
  const auto row = static_cast<uint32_t>(cells + 1);
  for (uint32_t j = 0; j < uint32_t(cells); ++j)
    for (uint32_t i = 0; i < uint32_t(cells); ++i) {
      const uint32_t v = j * row + i;
      m.triangles.push_back({v, v + 1, v + row});
      m.triangles.push_back({v + 1, v + row + 1, v + row});
    }
  return m;
}

}  // namespace surfinspect::bench
