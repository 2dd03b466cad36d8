// A synthetic organized scan of the plane z = 0 for the defect and plan
// tests: a side x side grid at 0.25 mm pitch starting at (5, 5) mm, normal
// noise, Gaussian dents and bumps, and any further height per pixel.
#pragma once

#include <cstdint>
#include <functional>
#include <random>
#include <vector>

#include "core/types/point_cloud.h"

namespace surfinspect::testing {

struct GaussianFeature {
  double cx_mm, cy_mm, amplitude_mm, sigma_mm;  // a < 0 a dent, a > 0 a bump
};

// z = noise + sum of the features + extra(row, col), rounded to float once.
// `rng` draws the noise, one value per pixel in row-major order.
PointCloud PlaneScan(uint32_t side, double noise_mm, const std::vector<GaussianFeature>& features,
                     std::mt19937_64& rng,
                     const std::function<double(uint32_t, uint32_t)>& extra = nullptr);

}  // namespace surfinspect::testing
