#include "core/plan/gaussian_fit.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

namespace surfinspect {

GaussianFit FitIsotropicGaussian(const std::vector<Eigen::Vector3d>& uvd,
                                 const std::vector<char>& keep, const GaussianFit& start) {
  Eigen::Matrix<double, 5, 1> x(start.amplitude, start.centre.x(), start.centre.y(),
                                std::log(start.sigma), start.baseline);
  auto cost_and_system = [&](const Eigen::Matrix<double, 5, 1>& p, Eigen::Matrix<double, 5, 5>* H,
                             Eigen::Matrix<double, 5, 1>* g) {
    const double s2 = std::exp(2 * p[3]);
    double cost = 0;
    if (H) H->setZero(), g->setZero();
    for (std::size_t k = 0; k < uvd.size(); ++k) {
      if (!keep[k]) continue;
      const double du = uvd[k].x() - p[1], dv = uvd[k].y() - p[2], r2 = du * du + dv * dv;
      const double e = std::exp(-r2 / (2 * s2));
      const double res = p[4] + p[0] * e - uvd[k].z();
      cost += res * res;
      if (!H) continue;
      const Eigen::Matrix<double, 5, 1> J(e, p[0] * e * du / s2, p[0] * e * dv / s2,
                                          p[0] * e * r2 / s2, 1.0);
      H->selfadjointView<Eigen::Lower>().rankUpdate(J);
      *g += J * res;
    }
    if (H) *H = H->selfadjointView<Eigen::Lower>();
    return cost;
  };
  double lambda = 1e-3;
  Eigen::Matrix<double, 5, 5> H;
  Eigen::Matrix<double, 5, 1> g;
  double cost = cost_and_system(x, &H, &g);
  for (int it = 0; it < 50; ++it) {
    Eigen::Matrix<double, 5, 5> A = H;
    A.diagonal() *= 1 + lambda;
    const Eigen::Matrix<double, 5, 1> step = A.ldlt().solve(-g);
    if (!step.allFinite()) break;
    const double trial = cost_and_system(x + step, nullptr, nullptr);
    if (trial < cost) {
      x += step;
      const bool done = cost - trial < 1e-12 * cost;
      cost = cost_and_system(x, &H, &g);
      lambda = std::max(lambda / 10, 1e-9);
      if (done) break;
    } else {
      lambda *= 10;
      if (lambda > 1e8) break;
    }
  }
  const std::size_t used = static_cast<std::size_t>(std::count(keep.begin(), keep.end(), 1));
  GaussianFit f;
  f.amplitude = x[0];
  f.centre = {x[1], x[2]};
  f.sigma = std::exp(x[3]);
  f.baseline = x[4];
  f.rms = used ? std::sqrt(cost / used) : NAN;
  f.ok = x.allFinite() && used >= 8;
  return f;
}

}  // namespace surfinspect
