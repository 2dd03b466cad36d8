#include "core/registration/locked_best_fit.h"

#include <gtest/gtest.h>

#include <random>

#include "absl/strings/string_view.h"
#include "core/simulation/pillar.h"
#include "tests/support/test_meshes.h"

namespace surfinspect {
namespace {

constexpr double kDeg = M_PI / 180;

::testing::AssertionResult Has(absl::string_view text, absl::string_view part) {
  if (text.find(part) != absl::string_view::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "\"" << text << "\" lacks \"" << part << "\"";
}

// A 200 x 120 mm sheet curved in both directions, so that it holds all six
// degrees of freedom.
TriangleMesh Sheet() {
  return testing::HeightField(-100, 100, -60, 60, 81, 49, [](double x, double y) {
    return 8 * std::sin(x / 25) * std::cos(y / 20) + 0.001 * x * x;
  });
}

// `n` points uniformly (by area) on the mesh's triangles, fixed seed.
std::vector<Eigen::Vector3d> Sample(const TriangleMesh& mesh, int n, uint32_t seed) {
  std::vector<double> area_sum;
  double total = 0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>(),
                          b = mesh.vertices[t[1]].cast<double>(),
                          c = mesh.vertices[t[2]].cast<double>();
    total += 0.5 * (b - a).cross(c - a).norm();
    area_sum.push_back(total);
  }
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < n; ++i) {
    const auto k =
        std::lower_bound(area_sum.begin(), area_sum.end(), u(rng) * total) - area_sum.begin();
    const auto& t = mesh.triangles[std::min<std::size_t>(k, mesh.triangles.size() - 1)];
    double s = std::sqrt(u(rng)), v = u(rng);  // uniform on the triangle
    out.push_back((1 - s) * mesh.vertices[t[0]].cast<double>() +
                  s * (1 - v) * mesh.vertices[t[1]].cast<double>() +
                  s * v * mesh.vertices[t[2]].cast<double>());
  }
  return out;
}

// A displacement of `mm` along `dir` and `deg` about `axis` through the origin.
Eigen::Isometry3d Displacement(Eigen::Vector3d dir, double mm, Eigen::Vector3d axis, double deg) {
  Eigen::Isometry3d d = Eigen::Isometry3d::Identity();
  d.translate(mm * dir.normalized()).rotate(Eigen::AngleAxisd(deg * kDeg, axis.normalized()));
  return d;
}

PointCloud Measured(const std::vector<Eigen::Vector3d>& nominal, const Eigen::Isometry3d& d) {
  std::vector<Eigen::Vector3f> pts;
  for (const auto& p : nominal) pts.push_back((d * p).cast<float>());
  return PointCloud::Unorganized(std::move(pts));
}

// How far two corrections place the sheet's extent apart: the largest
// distance between the images of the corners of its box, mm (a rigid
// motion's displacement is largest at a corner).
double ApartAtExtent(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  double worst = 0;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d c(k & 1 ? 100 : -100, k & 2 ? 60 : -60, k & 4 ? 20 : -10);
    worst = std::max(worst, (a * c - b * c).norm());
  }
  return worst;
}

class LockedBestFit : public ::testing::Test {
 protected:
  void SetUp() override {
    index_ = testing::IndexOf(Sheet());
    ASSERT_NE(index_, nullptr);
    nominal_ = Sample(index_->mesh(), 20000, 1);
  }
  absl::StatusOr<LockedBestFitResult> Fit(const PointCloud& points, const LockedDofs& locked = {},
                                          const LockedBestFitSettings& s = {},
                                          const std::vector<uint8_t>& mask = {}) {
    return RunLockedBestFit(*index_, points, mask, locked, s);
  }
  std::unique_ptr<MeshIndex> index_;
  std::vector<Eigen::Vector3d> nominal_;
};

TEST_F(LockedBestFit, UnlockedFitRecoversAPlantedMotion) {
  const Eigen::Isometry3d d = Displacement({1, -2, 1.5}, 0.6, {0.3, 1, -0.5}, 0.3);
  auto r = Fit(Measured(nominal_, d));
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_TRUE(r->converged);
  EXPECT_LT(r->iterations, 15);
  // The points are floats (rounding up to 4e-6 mm here): that, not the
  // solver, bounds the recovery.
  EXPECT_LT(ApartAtExtent(r->nominal_from_measured, d.inverse()), 1e-5);
  EXPECT_LT(r->rms_after_mm, 1e-5);
  EXPECT_GT(r->rms_before_mm, 0.1);
  EXPECT_EQ(r->rms_history_mm.front(), r->rms_before_mm);
  EXPECT_EQ(r->rms_history_mm.back(), r->rms_after_mm);
  EXPECT_EQ(r->rms_history_mm.size(), std::size_t(r->iterations) + 1);
  EXPECT_EQ(r->points_used, nominal_.size());
  EXPECT_EQ(r->inliers, nominal_.size());
  EXPECT_TRUE(std::isfinite(r->condition));
  EXPECT_FALSE(r->exceeds_max_correction);  // no maximum given
}

TEST_F(LockedBestFit, LockedComponentsStayExactlyZeroWhereTheUnlockedFitMovesThem) {
  const Eigen::Isometry3d d = Displacement({0.5, 0.3, -1}, 0.5, {1, 0.2, 0.4}, 0.25);
  const PointCloud points = Measured(nominal_, d);
  auto free_fit = Fit(points);
  ASSERT_TRUE(free_fit.ok()) << free_fit.status();
  LockedDofs locked;
  locked.tz = locked.rx = true;
  auto locked_fit = Fit(points, locked);
  ASSERT_TRUE(locked_fit.ok()) << locked_fit.status();
  // The unlocked fit moves both: it recovers the planted ~0.45 mm and ~0.23°.
  EXPECT_GT(std::abs(free_fit->x[kTz]), 0.3);
  EXPECT_GT(std::abs(free_fit->x[kRx]), 0.15 * kDeg);
  // The locked fit leaves them exactly at identity.
  EXPECT_EQ(locked_fit->x[kTz], 0.0);
  EXPECT_EQ(locked_fit->x[kRx], 0.0);
  const Eigen::Isometry3d& t = locked_fit->nominal_from_measured;
  EXPECT_EQ(t.translation().z(), 0.0);
  EXPECT_EQ(ParamsFromTransform(t)[kRx], 0.0);
  EXPECT_LE(std::abs(ParamsFromTransform(t)[kTz]), 1e-12);
  // The free components did move, and the fit is worse than the unlocked one.
  EXPECT_GT(locked_fit->x.cwiseAbs().maxCoeff(), 0.05);
  EXPECT_GT(locked_fit->rms_after_mm, 10 * free_fit->rms_after_mm);
  EXPECT_LT(locked_fit->rms_after_mm, locked_fit->rms_before_mm);
}

TEST_F(LockedBestFit, EveryLockedSetLeavesItsComponentsExactlyZero) {
  const Eigen::Isometry3d d = Displacement({-1, 0.5, 0.7}, 0.4, {0.2, -0.6, 1}, 0.2);
  const PointCloud points = Measured(nominal_, d);
  for (int mask = 1; mask < 64; mask += 5) {
    const LockedDofs locked{bool(mask & 1), bool(mask & 2),  bool(mask & 4),
                            bool(mask & 8), bool(mask & 16), bool(mask & 32)};
    auto r = Fit(points, locked);
    ASSERT_TRUE(r.ok()) << r.status();
    for (int k = 0; k < kRigidDofs; ++k)
      if (locked.IsLocked(k)) {
        EXPECT_EQ(r->x[k], 0.0) << "mask " << mask << " " << DofName(k);
      }
  }
}

TEST_F(LockedBestFit, AllLockedLeavesTheIdentity) {
  const LockedDofs all{true, true, true, true, true, true};
  auto r = Fit(Measured(nominal_, Displacement({1, 0, 0}, 0.2, {0, 0, 1}, 0.1)), all);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_TRUE(r->nominal_from_measured.matrix() == Eigen::Matrix4d::Identity());
  EXPECT_EQ(r->iterations, 0);
  EXPECT_TRUE(r->converged);
  EXPECT_EQ(r->rms_before_mm, r->rms_after_mm);
}

TEST_F(LockedBestFit, MaximumCorrectionIsReportedNotRefused) {
  const Eigen::Isometry3d d = Displacement({0, 1, 1}, 0.5, {1, 1, 0}, 0.3);
  const PointCloud points = Measured(nominal_, d);
  LockedBestFitSettings s;
  s.max_correction_mm = 2;
  s.max_correction_deg = 1;
  auto within = Fit(points, {}, s);
  ASSERT_TRUE(within.ok()) << within.status();
  EXPECT_FALSE(within->exceeds_max_correction);
  EXPECT_NEAR(within->correction_deg, 0.3, 1e-6);
  // A 0.3° turn about an axis through the origin adds up to ~0.6 mm at the
  // sheet's far points to the 0.5 mm shift.
  EXPECT_GT(within->correction_mm, 0.5);
  EXPECT_LT(within->correction_mm, 0.5 + 0.3 * kDeg * 117);
  s.max_correction_mm = 0.4;
  auto too_far = Fit(points, {}, s);
  ASSERT_TRUE(too_far.ok()) << too_far.status();
  EXPECT_TRUE(too_far->exceeds_max_correction);
  EXPECT_TRUE(too_far->x == within->x);  // the same fit, only judged
  s.max_correction_mm = 2;
  s.max_correction_deg = 0.2;
  EXPECT_TRUE(Fit(points, {}, s)->exceeds_max_correction);
}

TEST_F(LockedBestFit, RefusesAFitThePointsCannotHoldNamingTheFreeMotions) {
  auto flat = testing::IndexOf(testing::FlatSquare());
  ASSERT_NE(flat, nullptr);
  const std::vector<Eigen::Vector3d> on_plane = Sample(flat->mesh(), 2000, 2);
  const Eigen::Isometry3d d = Displacement({0, 0, 1}, 0.3, {1, -1, 0}, 0.2);
  const PointCloud points = Measured(on_plane, d);
  auto r = RunLockedBestFit(*flat, points, {}, {}, {});
  ASSERT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(Has(r.status().message(),
                  "the points leave free: translation along x, translation along y, rotation "
                  "about z"));
  // Locking them, the plane's own three are fitted: the planted motion has none of the others.
  LockedDofs locked;
  locked.tx = locked.ty = locked.rz = true;
  auto ok = RunLockedBestFit(*flat, points, {}, locked, {});
  ASSERT_TRUE(ok.ok()) << ok.status();
  const RigidParams truth = ParamsFromTransform(d.inverse());
  EXPECT_NEAR(ok->x[kTz], truth[kTz], 1e-5);
  EXPECT_NEAR(ok->x[kRx], truth[kRx], 1e-7);
  EXPECT_NEAR(ok->x[kRy], truth[kRy], 1e-7);
}

enum class Shape { kGaussian, kPlateau };

// The sheet with a shape error along z about (40, 15) — a Gaussian bump of
// 12 mm sigma, or a plateau 20 mm in radius with a step edge — and 15 µm
// noise, then displaced.
PointCloud BumpedAndNoisy(const std::vector<Eigen::Vector3d>& nominal, const Eigen::Isometry3d& d,
                          double bump_mm, Shape shape = Shape::kGaussian) {
  std::mt19937 rng(4);
  std::normal_distribution<double> noise(0, 0.015);
  std::vector<Eigen::Vector3d> shaped;
  for (const auto& p : nominal) {
    const double r2 = (p.head<2>() - Eigen::Vector2d(40, 15)).squaredNorm();
    const double bump = shape == Shape::kGaussian ? bump_mm * std::exp(-r2 / (2 * 12 * 12))
                                                  : (r2 < 20 * 20 ? bump_mm : 0);
    shaped.push_back(p + Eigen::Vector3d(noise(rng), noise(rng), noise(rng) + bump));
  }
  return Measured(shaped, d);
}

// Pose errors at the sheet's extent of the least-squares, Huber and Tukey
// fits, mm.
struct KernelErrors {
  double least_squares, huber, tukey;
};

TEST_F(LockedBestFit, RobustFitIsNotDraggedFarByALocalShapeError) {
  const Eigen::Isometry3d d = Displacement({1, 1, -1}, 0.7, {-0.5, 1, 0.3}, 0.4);
  auto errors = [&](const PointCloud& points) {
    LockedBestFitSettings plain, huber;
    plain.kernel = RobustKernel::kNone;
    huber.kernel = RobustKernel::kHuber;
    huber.kernel_sigmas = 1.345;
    auto a = Fit(points, {}, plain), b = Fit(points, {}, huber), c = Fit(points);
    EXPECT_TRUE(a.ok() && b.ok() && c.ok());
    EXPECT_TRUE(c->converged);
    EXPECT_NEAR(c->scale_mm, 0.015, 0.005);  // σ of the MAD: the noise, not the bump
    return KernelErrors{ApartAtExtent(a->nominal_from_measured, d.inverse()),
                        ApartAtExtent(b->nominal_from_measured, d.inverse()),
                        ApartAtExtent(c->nominal_from_measured, d.inverse())};
  };
  const KernelErrors noise = errors(BumpedAndNoisy(nominal_, d, 0));
  const KernelErrors gauss = errors(BumpedAndNoisy(nominal_, d, 0.3));
  const KernelErrors plateau = errors(BumpedAndNoisy(nominal_, d, 0.3, Shape::kPlateau));
  std::printf(
      "pose error at the extent, mm (least squares / Huber / Tukey): noise only "
      "%.4f / %.4f / %.4f, 0.3 mm Gaussian bump %.4f / %.4f / %.4f, 0.3 mm plateau "
      "%.4f / %.4f / %.4f\n",
      noise.least_squares, noise.huber, noise.tukey, gauss.least_squares, gauss.huber, gauss.tukey,
      plateau.least_squares, plateau.huber, plateau.tukey);
  // 15 µm noise on 20000 points moves no fit by more than a few µm.
  EXPECT_LT(noise.tukey, 0.005);
  EXPECT_LT(noise.least_squares, 0.005);
  // A step-edged plateau lies beyond Tukey's cut-off and drops out; least
  // squares tilts towards it by a large part of its height.
  EXPECT_LT(plateau.tukey, 0.005);
  EXPECT_GT(plateau.least_squares, 0.1);
  // A smooth bump's flanks lie within the cut-off (noise-sized there), so
  // some pull remains: Tukey keeps it to a fraction of least squares'.
  EXPECT_LT(gauss.tukey, 0.03);
  EXPECT_LT(gauss.tukey, 0.2 * gauss.least_squares);
  EXPECT_LT(gauss.huber, 0.5 * gauss.least_squares);
}

TEST_F(LockedBestFit, ResultDoesNotDependOnTheThreadCount) {
  const std::vector<Eigen::Vector3d> many = Sample(index_->mesh(), 50000, 3);
  const PointCloud points =
      BumpedAndNoisy(many, Displacement({2, -1, 1}, 0.8, {1, 2, 3}, 0.35), 0.3);
  LockedDofs locked;
  locked.ry = true;
  std::vector<LockedBestFitResult> runs;
  for (int threads : {1, 2, 3, 8}) {
    LockedBestFitSettings s;
    s.threads = threads;
    auto r = Fit(points, locked, s);
    ASSERT_TRUE(r.ok()) << r.status();
    runs.push_back(*r);
  }
  for (const auto& r : runs) {
    EXPECT_TRUE(r.x == runs[0].x);  // bit for bit
    EXPECT_EQ(r.iterations, runs[0].iterations);
    EXPECT_EQ(r.rms_after_mm, runs[0].rms_after_mm);
    EXPECT_EQ(r.rms_history_mm, runs[0].rms_history_mm);
    EXPECT_EQ(r.inliers, runs[0].inliers);
    EXPECT_EQ(r.scale_mm, runs[0].scale_mm);
    EXPECT_EQ(r.correction_mm, runs[0].correction_mm);
  }
}

TEST_F(LockedBestFit, NaNPointsAreNoDataAndChangeNothing) {
  const Eigen::Isometry3d d = Displacement({1, 0, 1}, 0.3, {0, 1, 0}, 0.1);
  const PointCloud points = BumpedAndNoisy(nominal_, d, 0);
  PointCloud holes = PointCloud::Organized(400, 100);  // every other pixel without data
  for (std::size_t i = 0; i < points.size(); ++i) holes.points[2 * i] = points.points[i];
  auto a = Fit(points);
  auto b = Fit(holes);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(b->points_used, a->points_used);
  // Other chunks, so other rounding in the sums: equal to far below the noise.
  EXPECT_LT((a->x - b->x).cwiseAbs().maxCoeff(), 1e-10);
}

TEST_F(LockedBestFit, RegionMaskRestrictsThePairs) {
  // The triangles with x > 0: the fit uses only the points above them.
  std::vector<uint8_t> right(index_->mesh().triangles.size(), 0);
  std::size_t in_region = 0;
  for (std::size_t t = 0; t < right.size(); ++t)
    right[t] = index_->mesh().vertices[index_->mesh().triangles[t][0]].x() >= 0 ? 1 : 0;
  for (const auto& p : nominal_) in_region += p.x() > 0.5 ? 1 : 0;
  const Eigen::Isometry3d d = Displacement({0, 1, 0}, 0.2, {1, 0, 0}, 0.1);
  auto r = Fit(Measured(nominal_, d), {}, {}, right);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_NEAR(double(r->points_used), double(in_region), 0.03 * in_region);
  EXPECT_LT(r->points_used, nominal_.size() * 6 / 10);
  EXPECT_LT(ApartAtExtent(r->nominal_from_measured, d.inverse()), 1e-4);
}

TEST(LockedBestFitPillar, LockingTheExtrusionAxisOnThePillar) {
  // The demo's hat channel, extruded along x and sagging 3 mm towards its
  // ends: x is held by the sag alone, the case a plant locks.
  auto index = testing::IndexOf(MakePillarMesh(300));
  ASSERT_NE(index, nullptr);
  const std::vector<Eigen::Vector3d> nominal = Sample(index->mesh(), 30000, 5);
  const Eigen::Isometry3d d = Displacement({1, 0.5, -0.5}, 0.6, {0.2, 1, 0.5}, 0.3);
  const PointCloud points = Measured(nominal, d);
  auto free_fit = RunLockedBestFit(*index, points, {}, {}, {});
  ASSERT_TRUE(free_fit.ok()) << free_fit.status();
  EXPECT_LT((free_fit->x - ParamsFromTransform(d.inverse())).cwiseAbs().maxCoeff(), 1e-5);
  LockedDofs locked;
  locked.tx = true;
  auto locked_fit = RunLockedBestFit(*index, points, {}, locked, {});
  ASSERT_TRUE(locked_fit.ok()) << locked_fit.status();
  std::printf("pillar: free tx %.4f mm, condition %.3g; locked tx %.17g\n", free_fit->x[kTx],
              free_fit->condition, locked_fit->x[kTx]);
  EXPECT_GT(std::abs(free_fit->x[kTx]), 0.3);
  EXPECT_EQ(locked_fit->x[kTx], 0.0);
  EXPECT_EQ(locked_fit->nominal_from_measured.translation().x(), 0.0);
}

TEST_F(LockedBestFit, RefusesBadInputNamingTheField) {
  auto message = [&](const PointCloud& points, const LockedBestFitSettings& s = {},
                     const std::vector<uint8_t>& mask = {}) {
    auto r = Fit(points, {}, s, mask);
    EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument) << r.status();
    return std::string(r.status().message());
  };
  const PointCloud good = Measured(nominal_, Eigen::Isometry3d::Identity());
  EXPECT_TRUE(Has(message(PointCloud::Unorganized({})), "points_in_part has 0 valid points"));
  EXPECT_TRUE(Has(message(PointCloud::Organized(10, 10)), "points_in_part has 0 valid points"));
  PointCloud inf = good;
  inf.points[3].y() = INFINITY;
  EXPECT_TRUE(Has(message(inf), "points_in_part: cloud: point 3 has an infinite coordinate"));
  EXPECT_TRUE(
      Has(message(good, {}, std::vector<uint8_t>(3, 1)), "triangle_mask has 3 entries for"));
  const std::vector<uint8_t> none(index_->mesh().triangles.size(), 0);
  EXPECT_TRUE(Has(message(good, {}, none), "only 0 points lie within max_correspondence_mm"));
  EXPECT_TRUE(Has(message(Measured(nominal_, Displacement({0, 0, 1}, 50, {0, 0, 1}, 0))),
                  "only 0 points lie within"));
  auto bad = [&](auto set, absl::string_view field) {
    LockedBestFitSettings s;
    set(s);
    EXPECT_TRUE(Has(message(good, s), field));
  };
  bad([](auto& s) { s.max_iterations = 0; }, "max_iterations");
  bad([](auto& s) { s.max_correspondence_mm = NAN; }, "max_correspondence_mm");
  bad([](auto& s) { s.kernel_sigmas = 0; }, "kernel_sigmas");
  bad([](auto& s) { s.min_scale_mm = -1; }, "min_scale_mm");
  bad([](auto& s) { s.convergence_mm = INFINITY; }, "convergence_mm");
  bad([](auto& s) { s.max_correction_mm = NAN; }, "max_correction_mm");
  bad([](auto& s) { s.max_correction_deg = 0; }, "max_correction_deg");
  bad([](auto& s) { s.threads = -1; }, "threads");
  EXPECT_TRUE(ValidateLockedBestFitSettings({}).ok());
}

TEST_F(LockedBestFit, CancelStops) {
  std::atomic<bool> cancel{true};
  auto r = RunLockedBestFit(*index_, Measured(nominal_, Eigen::Isometry3d::Identity()), {}, {}, {},
                            &cancel);
  EXPECT_EQ(r.status().code(), absl::StatusCode::kCancelled);
}

}  // namespace
}  // namespace surfinspect
