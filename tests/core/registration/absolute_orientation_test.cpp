#include "core/registration/absolute_orientation.h"

#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <random>

namespace surfinspect {
namespace {

// Independent oracle: Kabsch / Umeyama via SVD of the weighted covariance.
Eigen::Isometry3d Kabsch(const std::vector<Eigen::Vector3d>& a,
                         const std::vector<Eigen::Vector3d>& b, const std::vector<double>& w) {
  double ws = 0;
  Eigen::Vector3d ca = Eigen::Vector3d::Zero(), cb = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < a.size(); ++i) ws += w[i], ca += w[i] * a[i], cb += w[i] * b[i];
  ca /= ws;
  cb /= ws;
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < a.size(); ++i) h += w[i] * (a[i] - ca) * (b[i] - cb).transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1 : 1;
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = svd.matrixV() * d * svd.matrixU().transpose();
  t.translation() = cb - t.linear() * ca;
  return t;
}

TEST(HornAbsoluteOrientation, MatchesKabschOnRandomNoisySets) {
  std::mt19937 rng(11);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(0.1, 2.0);
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 3 + trial % 40;
    Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
    truth.linear() =
        Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
    truth.translation() = 100 * Eigen::Vector3d(g(rng), g(rng), g(rng));
    std::vector<Eigen::Vector3d> a, b;
    std::vector<double> w;
    for (int i = 0; i < n; ++i) {
      a.push_back(50 * Eigen::Vector3d(g(rng), g(rng), g(rng)));
      b.push_back(truth * a.back() + 0.5 * Eigen::Vector3d(g(rng), g(rng), g(rng)));
      w.push_back(trial % 2 ? u(rng) : 1.0);
    }
    auto horn = HornAbsoluteOrientation(a, b, trial % 2 ? w : std::vector<double>{});
    ASSERT_TRUE(horn.ok()) << horn.status();
    const Eigen::Isometry3d oracle = Kabsch(a, b, w);
    EXPECT_LT((horn->matrix() - oracle.matrix()).cwiseAbs().maxCoeff(), 1e-8) << "trial " << trial;
  }
}

TEST(HornAbsoluteOrientation, RecoversExactTransform) {
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  truth.linear() =
      Eigen::AngleAxisd(2.5, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  truth.translation() = Eigen::Vector3d(400, -20, 7);
  std::vector<Eigen::Vector3d> a = {{0, 0, 0}, {10, 0, 0}, {0, 20, 0}, {3, 4, 30}}, b;
  for (const auto& p : a) b.push_back(truth * p);
  auto t = HornAbsoluteOrientation(a, b);
  ASSERT_TRUE(t.ok());
  EXPECT_LT((t->matrix() - truth.matrix()).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(HornAbsoluteOrientation, RejectsDegenerateInput) {
  const std::vector<Eigen::Vector3d> line = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {5, 5, 5}};
  EXPECT_FALSE(HornAbsoluteOrientation(line, line).ok());
  EXPECT_FALSE(HornAbsoluteOrientation({{0, 0, 0}, {1, 0, 0}}, {{0, 0, 0}, {1, 0, 0}}).ok());
  EXPECT_FALSE(HornAbsoluteOrientation({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 0, 0}}).ok());
  EXPECT_FALSE(HornAbsoluteOrientation({{0, 0, NAN}, {1, 0, 0}, {0, 1, 0}},
                                       {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}})
                   .ok());
  EXPECT_FALSE(HornAbsoluteOrientation({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}},
                                       {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 0, 0})
                   .ok());
}

}  // namespace
}  // namespace surfinspect
