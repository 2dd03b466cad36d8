#include "core/plan/gaussian_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace surfinspect {
namespace {

// Samples of c + A exp(-|x - x0|^2 / (2 s^2)) on a 0.25 mm grid over
// [-8, 8]^2, plus Gaussian noise.
std::vector<Eigen::Vector3d> Samples(double a, Eigen::Vector2d x0, double s, double c, double noise,
                                     uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0, noise > 0 ? noise : 1);
  std::vector<Eigen::Vector3d> out;
  for (double u = -8; u <= 8; u += 0.25)
    for (double v = -8; v <= 8; v += 0.25) {
      const double r2 = (Eigen::Vector2d(u, v) - x0).squaredNorm();
      out.emplace_back(u, v, c + a * std::exp(-r2 / (2 * s * s)) + (noise > 0 ? g(rng) : 0));
    }
  return out;
}

GaussianFit Start() {
  GaussianFit s;
  s.amplitude = -0.2;
  s.sigma = 1.5;
  return s;
}

TEST(GaussianFit, RecoversExactParameters) {
  const auto uvd = Samples(-0.3, {0.4, -0.2}, 2.0, 0.01, 0, 1);
  const GaussianFit f = FitIsotropicGaussian(uvd, std::vector<char>(uvd.size(), 1), Start());
  ASSERT_TRUE(f.ok);
  EXPECT_NEAR(f.amplitude, -0.3, 1e-8);
  EXPECT_NEAR(f.centre.x(), 0.4, 1e-7);
  EXPECT_NEAR(f.centre.y(), -0.2, 1e-7);
  EXPECT_NEAR(f.sigma, 2.0, 1e-7);
  EXPECT_NEAR(f.baseline, 0.01, 1e-8);
  EXPECT_LT(f.rms, 1e-8);
}

TEST(GaussianFit, IgnoresSamplesNotKeptAndAveragesNoise) {
  auto uvd = Samples(0.15, {-1, 2}, 3.0, 0, 0.015, 2);
  std::vector<char> keep(uvd.size(), 1);
  for (std::size_t k = 0; k < uvd.size(); k += 97) uvd[k].z() += 5, keep[k] = 0;  // spikes
  const GaussianFit f = FitIsotropicGaussian(uvd, keep, Start());
  ASSERT_TRUE(f.ok);
  // ~4000 samples: the amplitude's standard error is ~1 um.
  EXPECT_NEAR(f.amplitude + f.baseline, 0.15, 0.005);
  EXPECT_NEAR(f.sigma, 3.0, 0.05);
  EXPECT_NEAR(f.rms, 0.015, 0.001);
}

TEST(GaussianFit, TooFewSamplesIsNotOk) {
  const std::vector<Eigen::Vector3d> uvd = {{0, 0, 1}, {1, 0, 0.5}, {0, 1, 0.5}};
  EXPECT_FALSE(FitIsotropicGaussian(uvd, std::vector<char>(3, 1), Start()).ok);
}

}  // namespace
}  // namespace surfinspect
