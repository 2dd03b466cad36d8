#include "core/registration/rps_fit.h"

#include <gtest/gtest.h>

#include <random>

#include "absl/strings/string_view.h"

namespace surfinspect {
namespace {

// Whether `text` holds `part`, showing the text when not.
::testing::AssertionResult Has(absl::string_view text, absl::string_view part) {
  if (text.find(part) != absl::string_view::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "\"" << text << "\" lacks \"" << part << "\"";
}

constexpr double kDeg = M_PI / 180;

// A synthetic part about 300 x 150 x 80 mm whose centre lies far from the
// part frame's origin (so rotations and translations couple in x): two
// locating holes in its top (each locking x and y) and four surface points
// with normals in different directions.
const Eigen::Vector3d kCentre(420, -150, 80);

std::vector<RpsReference> Drawing() {
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(),
                        z = Eigen::Vector3d::UnitZ();
  auto ref = [](std::string name, Eigen::Vector3d at, std::vector<Eigen::Vector3d> dirs) {
    RpsReference r;
    r.name = std::move(name);
    r.nominal_mm = kCentre + at;
    r.measured_mm = r.nominal_mm;
    r.directions = std::move(dirs);
    return r;
  };
  return {ref("H1", {-125, 0, 0}, {x, y}),
          ref("H2", {130, 10, 0}, {x, y}),
          ref("S1", {-100, 45, 0}, {z}),
          ref("S2", {110, -50, 0}, {z}),
          ref("S3", {0, 75, -40}, {Eigen::Vector3d(0, 0.6, 0.8)}),
          ref("S4", {30, -75, -60}, {Eigen::Vector3d(0, -0.8, 0.6)})};
}

// A fixture displacement: `mm` along a random direction and `deg` about a
// random axis through the part's centre (measured = displacement · nominal).
Eigen::Isometry3d Displacement(std::mt19937& rng, double mm, double deg) {
  std::normal_distribution<double> g;
  const Eigen::Vector3d axis = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
  const Eigen::Vector3d dir = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
  Eigen::Isometry3d d = Eigen::Isometry3d::Identity();
  d.translate(mm * dir + kCentre).rotate(Eigen::AngleAxisd(deg * kDeg, axis)).translate(-kCentre);
  return d;
}

// The measured points of a part displaced by `displacement`: each feature
// moved with the part, and slid along what it does not lock (a surface point
// along its surface, a hole centre along its axis), which the solve must
// ignore.
std::vector<RpsReference> Measure(const Eigen::Isometry3d& displacement) {
  std::vector<RpsReference> refs = Drawing();
  for (std::size_t i = 0; i < refs.size(); ++i) {
    RpsReference& r = refs[i];
    Eigen::Vector3d slide = Eigen::Vector3d(0.3, -0.2, 0.25 + 0.1 * i);
    for (const auto& d : r.directions) slide -= d.dot(slide) * d;
    r.measured_mm = displacement * (r.nominal_mm + slide);
  }
  return refs;
}

TEST(RpsFit, RecoversPlantedDisplacementsFromExactData) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> mm(0.1, 1.0), deg(0.05, 0.5);
  double worst = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const Eigen::Isometry3d displacement = Displacement(rng, mm(rng), deg(rng));
    const RigidParams truth = ParamsFromTransform(displacement.inverse());
    auto r = SolveRps(Measure(displacement));
    ASSERT_TRUE(r.ok()) << r.status();
    EXPECT_TRUE(r->converged);
    EXPECT_LE(r->iterations, 6);  // Gauss-Newton on a zero-residual problem: quadratic
    EXPECT_EQ(r->equations, 8);
    worst = std::max(worst, (r->x - truth).cwiseAbs().maxCoeff());
    EXPECT_LT(r->rms_after_mm, 1e-9);
    EXPECT_GT(r->rms_before_mm, 0.01);
    ASSERT_EQ(r->residuals.size(), 6u);
    for (const auto& res : r->residuals)
      for (double after : res.after_mm) EXPECT_LT(std::abs(after), 1e-9);
    EXPECT_TRUE(r->nominal_from_measured.isApprox(displacement.inverse(), 1e-12));
  }
  std::printf("exact data, 30 displacements: largest error of x %.2g (mm, rad)\n", worst);
  EXPECT_LT(worst, 1e-9);  // mm and rad
}

TEST(RpsFit, ReportsEachReferencesDeviationBeforeAlongItsDirections) {
  std::mt19937 rng(8);
  const Eigen::Isometry3d displacement = Displacement(rng, 0.6, 0.3);
  const std::vector<RpsReference> refs = Measure(displacement);
  auto r = SolveRps(refs);
  ASSERT_TRUE(r.ok()) << r.status();
  double sum2 = 0;
  for (std::size_t i = 0; i < refs.size(); ++i) {
    ASSERT_EQ(r->residuals[i].before_mm.size(), refs[i].directions.size());
    for (std::size_t k = 0; k < refs[i].directions.size(); ++k) {
      const double expected = refs[i].directions[k].dot(refs[i].measured_mm - refs[i].nominal_mm);
      EXPECT_DOUBLE_EQ(r->residuals[i].before_mm[k], expected);
      sum2 += expected * expected;
    }
  }
  EXPECT_NEAR(r->rms_before_mm, std::sqrt(sum2 / 8), 1e-15);
  EXPECT_GT(r->condition, 1);
  EXPECT_LT(r->condition, 1e3);  // a well-spread set
}

// Noise σ on every coordinate of the measured points: with orthonormal
// directions per reference each equation gets independent noise σ, so to
// first order cov(x̂) = σ²·(JᵀJ)⁻¹ (J the equations' Jacobian). 400 trials
// must show that spread: the RMS error of each component within ±15% of
// its predicted σ_k (4 standard errors of an RMS over 400 samples), and no
// error beyond 5 σ_k.
TEST(RpsFit, NoiseSpreadsTheSolutionAsLeastSquaresPredicts) {
  std::mt19937 rng(9);
  const double sigma_mm = 0.015;
  const Eigen::Isometry3d displacement = Displacement(rng, 0.8, 0.4);
  const RigidParams truth = ParamsFromTransform(displacement.inverse());
  const std::vector<RpsReference> exact = Measure(displacement);
  Eigen::MatrixXd j(8, kRigidDofs);
  const RigidMotion at_truth(truth);
  int e = 0;
  for (const auto& r : exact)
    for (const auto& d : r.directions)
      j.row(e++) = d.transpose() * at_truth.Jacobian(r.measured_mm);
  const DofMatrix cov = sigma_mm * sigma_mm * (j.transpose() * j).inverse();
  const RigidParams predicted = cov.diagonal().cwiseSqrt();

  std::normal_distribution<double> noise(0, sigma_mm);
  RigidParams sum2 = RigidParams::Zero(), worst = RigidParams::Zero();
  const int trials = 400;
  for (int t = 0; t < trials; ++t) {
    std::vector<RpsReference> refs = exact;
    for (auto& r : refs) r.measured_mm += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    auto r = SolveRps(refs);
    ASSERT_TRUE(r.ok()) << r.status();
    const RigidParams err = r->x - truth;
    sum2 += err.cwiseProduct(err);
    worst = worst.cwiseMax(err.cwiseAbs());
  }
  const RigidParams rms = (sum2 / trials).cwiseSqrt();
  std::printf("15 µm noise, %d trials: predicted / measured RMS error, µm and millidegrees: ",
              trials);
  for (int k = 0; k < kRigidDofs; ++k) {
    const double unit = k < 3 ? 1e3 : 1e3 / kDeg;
    std::printf("%s %.2f / %.2f; ", DofName(k), predicted[k] * unit, rms[k] * unit);
  }
  std::printf("\n");
  for (int k = 0; k < kRigidDofs; ++k) {
    EXPECT_GT(rms[k], 0.85 * predicted[k]) << DofName(k);
    EXPECT_LT(rms[k], 1.15 * predicted[k]) << DofName(k);
    EXPECT_LT(worst[k], 5 * predicted[k]) << DofName(k);
  }
  // The predicted spread itself: under 0.01° in rotation, and under 50 µm
  // in translation at the frame's origin, 450 mm from the part, where each
  // rotation error carries a lever arm.
  EXPECT_LT(predicted.head<3>().maxCoeff(), 0.05);
  EXPECT_LT(predicted.tail<3>().maxCoeff() / kDeg, 0.01);
}

TEST(RpsFit, SolutionIsAStationaryMinimumOfTheWeightedCost) {
  std::mt19937 rng(10);
  std::normal_distribution<double> noise(0, 0.05);
  std::vector<RpsReference> refs = Measure(Displacement(rng, 0.5, 0.2));
  for (std::size_t i = 0; i < refs.size(); ++i) {
    refs[i].measured_mm += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    refs[i].weight = 0.5 + i;
  }
  auto r = SolveRps(refs);
  ASSERT_TRUE(r.ok()) << r.status();
  auto cost = [&](const RigidParams& x) {
    const Eigen::Isometry3d t = RigidMotion(x).transform();
    double c = 0;
    for (const auto& ref : refs)
      for (const auto& d : ref.directions)
        c += ref.weight * std::pow(d.dot(t * ref.measured_mm - ref.nominal_mm), 2);
    return c;
  };
  const double at = cost(r->x);
  for (int k = 0; k < kRigidDofs; ++k) {
    const double h = k < 3 ? 1e-4 : 1e-7;  // mm, rad: comparable moves at ~500 mm
    RigidParams a = r->x, b = r->x;
    a[k] += h;
    b[k] -= h;
    EXPECT_GT(cost(a), at) << DofName(k);
    EXPECT_GT(cost(b), at) << DofName(k);
    // The gradient (central difference) vanishes against the curvature.
    EXPECT_LT(std::abs(cost(a) - cost(b)), 1e-6 * (cost(a) + cost(b) - 2 * at)) << DofName(k);
  }
  // The reported RMS is the weighted one.
  double wsum = 0;
  for (const auto& ref : refs) wsum += ref.weight * ref.directions.size();
  EXPECT_NEAR(r->rms_after_mm, std::sqrt(at / wsum), 1e-12);
}

TEST(RpsFit, RefusesThreeCollinearSurfacePointsNamingTheFreeMotions) {
  std::vector<RpsReference> refs = Drawing();
  std::vector<RpsReference> line;
  for (double x : {-100.0, 0.0, 100.0}) {
    RpsReference r = refs[2];
    r.nominal_mm = r.measured_mm = kCentre + Eigen::Vector3d(x, 0, 0);
    line.push_back(r);
  }
  auto r = SolveRps(line);
  ASSERT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(Has(r.status().message(),
                  "the references leave free: translation along x, translation along y, "
                  "rotation about x, rotation about z"));
}

TEST(RpsFit, RefusesOneHoleAloneNamingTheFreeMotions) {
  auto r = SolveRps({Drawing()[0]});
  ASSERT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(Has(r.status().message(),
                  "leave free: translation along z, rotation about x, rotation about y, "
                  "rotation about z"));
}

TEST(RpsFit, RefusesTwoHolesAloneAndTwoHolesWithALineOfSurfacePoints) {
  std::vector<RpsReference> refs = Drawing();
  auto holes = SolveRps({refs[0], refs[1]});
  ASSERT_EQ(holes.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(Has(holes.status().message(),
                  "leave free: translation along z, rotation about x, rotation about y ("));
  // Surface points on the line through the holes cannot hold the roll about it.
  std::vector<RpsReference> set = {refs[0], refs[1]};
  for (double x : {-60.0, 0.0, 60.0}) {
    RpsReference s = refs[2];
    s.nominal_mm = s.measured_mm = kCentre + Eigen::Vector3d(x, 0.04 * x, 0);
    set.push_back(s);
  }
  auto rolled = SolveRps(set);
  ASSERT_EQ(rolled.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(Has(rolled.status().message(), "leave free: rotation about x"));
  // A fourth point off that line locks it.
  set.push_back(refs[3]);
  EXPECT_TRUE(SolveRps(set).ok());
}

TEST(RpsFit, RefusesBadInputNamingTheField) {
  auto message = [](std::vector<RpsReference> refs, RpsSettings s = {}) {
    auto r = SolveRps(refs, s);
    EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
    return std::string(r.status().message());
  };
  EXPECT_TRUE(Has(message({}), "references is empty"));
  std::vector<RpsReference> refs = Drawing();
  refs[2].measured_mm.x() = NAN;
  EXPECT_TRUE(Has(message(refs), "references[2] (S1).measured_mm is not finite"));
  refs = Drawing();
  refs[3].nominal_mm.z() = INFINITY;
  EXPECT_TRUE(Has(message(refs), "references[3] (S2).nominal_mm is not finite"));
  refs = Drawing();
  refs[1].directions[1] = Eigen::Vector3d::Zero();
  EXPECT_TRUE(Has(message(refs), "references[1] (H2).directions[1] must be a unit vector"));
  refs = Drawing();
  refs[4].directions[0] = Eigen::Vector3d(NAN, 0, 0);
  EXPECT_TRUE(Has(message(refs), "references[4] (S3).directions[0] must be a unit vector"));
  refs = Drawing();
  refs[0].directions[1] = refs[0].directions[0];
  EXPECT_TRUE(Has(message(refs), "references[0] (H1).directions are not linearly independent"));
  refs = Drawing();
  refs[5].directions.clear();
  EXPECT_TRUE(Has(message(refs), "references[5] (S4).directions must hold 1 to 3"));
  refs[5].directions.assign(4, Eigen::Vector3d::UnitZ());
  EXPECT_TRUE(Has(message(refs), "references[5] (S4).directions must hold 1 to 3"));
  refs = Drawing();
  refs[2].weight = 0;
  EXPECT_TRUE(Has(message(refs), "references[2] (S1).weight must be finite and > 0"));
  refs[2].weight = NAN;
  EXPECT_TRUE(Has(message(refs), "references[2] (S1).weight"));
  refs = Drawing();
  refs[2].name.clear();
  refs[2].weight = -1;
  EXPECT_TRUE(Has(message(refs), "references[2].weight"));
  RpsSettings s;
  s.max_iterations = 0;
  EXPECT_TRUE(Has(message(Drawing(), s), "max_iterations"));
  s = {};
  s.part_extent_mm = -1;
  EXPECT_TRUE(Has(message(Drawing(), s), "part_extent_mm"));
}

TEST(RpsFit, ThreeDirectionsAtOnePointAndAGivenExtentAreAccepted) {
  // A 3-2-1 style set: one point locked in all three directions, one in two,
  // one in one, spread over the part.
  std::vector<RpsReference> refs = Drawing();
  refs[0].directions = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                        Eigen::Vector3d::UnitZ()};
  refs[1].directions = {Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()};
  std::vector<RpsReference> set = {refs[0], refs[1], refs[3]};
  std::mt19937 rng(12);
  const Eigen::Isometry3d displacement = Displacement(rng, 0.4, 0.2);
  for (auto& r : set) r.measured_mm = displacement * r.nominal_mm;
  RpsSettings s;
  s.part_extent_mm = 300;
  auto r = SolveRps(set, s);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(r->equations, 6);  // exactly determined
  EXPECT_LT((r->x - ParamsFromTransform(displacement.inverse())).cwiseAbs().maxCoeff(), 1e-9);
}

}  // namespace
}  // namespace surfinspect
