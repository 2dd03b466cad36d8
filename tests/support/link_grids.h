// Organized test grids for the link clustering (core/filter): random grids
// at a 0.5 mm link distance's scale, and the brute-force grid oracle that
// the grid path's tests compare against.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "core/types/point_cloud.h"

namespace surfinspect::testing {

// A grid at 0.3 mm pitch whose heights jump randomly, so that roughly half
// the straight and fewer of the diagonal links hold (at 0.5 mm), with
// `hole_fraction` of the pixels without data, in several spellings of NaN.
PointCloud RandomGrid(std::mt19937& rng, uint32_t w, uint32_t h, double hole_fraction);

// Brute-force oracle for the grid: BFS from every unvisited valid pixel over
// the 4 or 8 (`connectivity`) grid neighbours, linking with PointsLinked at
// squared distance r2. Per pixel its component, numbered in order of each
// component's first pixel, or LinkClusteringResult::kInvalid without data.
std::vector<int32_t> GridOracle(const PointCloud& c, int connectivity, float r2);

}  // namespace surfinspect::testing
