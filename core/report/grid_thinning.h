// Grid thinning of a quantised cloud for display (core/report/html_payload.h
// explains the rule): at most max_points points, one or a few per grid
// cell, the largest priorities first within a cell. Deterministic: the same
// input gives the same points in the same order (Morton order of the cells).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace surfinspect {

struct ThinningResult {
  std::vector<uint32_t> kept;  // indices into the input, Morton order; all of them unthinned
  int level = -1;              // cells of 2^level quantisation steps per axis; -1 = not thinned
  int per_cell = 0;            // finer cells (or points) kept per cell, 1..8 (any count at level 0)
  std::size_t cells = 0;       // occupied cells at `level`
};

// Spreads the low 16 bits of each coordinate into a 48-bit Morton code
// (x in bit 0, y in bit 1, z in bit 2 of every triple).
uint64_t MortonCode48(uint16_t x, uint16_t y, uint16_t z);

// `xyz` holds 3 quantised coordinates per point, `priority` one value per
// point (higher is kept first; ties go to the lower Morton code, then the
// lower index). max_points >= 1.
ThinningResult ThinOnGrid(const std::vector<uint16_t>& xyz, const std::vector<float>& priority,
                          std::size_t max_points);

}  // namespace surfinspect
