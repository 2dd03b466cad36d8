#include "tests/support/plane_scan.h"

#include <cmath>

namespace surfinspect::testing {

PointCloud PlaneScan(uint32_t side, double noise_mm, const std::vector<GaussianFeature>& features,
                     std::mt19937_64& rng, const std::function<double(uint32_t, uint32_t)>& extra) {
  PointCloud cloud = PointCloud::Organized(side, side);
  std::normal_distribution<double> noise(0, noise_mm);
  for (uint32_t r = 0; r < side; ++r)
    for (uint32_t c = 0; c < side; ++c) {
      const double x = 5 + 0.25 * c, y = 5 + 0.25 * r;
      double z = noise(rng);
      for (const GaussianFeature& f : features)
        z += f.amplitude_mm *
             std::exp(-((x - f.cx_mm) * (x - f.cx_mm) + (y - f.cy_mm) * (y - f.cy_mm)) /
                      (2 * f.sigma_mm * f.sigma_mm));
      if (extra) z += extra(r, c);
      cloud.points[r * side + c] = Eigen::Vector3d(x, y, z).cast<float>();
    }
  return cloud;
}

}  // namespace surfinspect::testing
