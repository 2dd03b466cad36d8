// The acceptance test against the simulator's truth (core/simulation/acceptance_artefacts.cpp
// and core/acceptance/cell_acceptance.cpp together): planted errors come back,
// a viewpoint calibrated 30 µm off fails SD exactly where it is used, and the
// cross-view SD errors agree with the σ the calibrations report.
//
// Every scan is ray-cast once, noise-free; seeded runs add Gaussian noise
// along each pixel's ray, the simulator's own noise model
// (core/simulation/scan_simulator.h), so 20 seeded cells need no new ray
// casting: each run is noise, the link-clustering filter and the fits.
#include "core/simulation/acceptance_artefacts.h"

#include <gtest/gtest.h>

#include <random>
#include <set>

#include "core/acceptance/cell_acceptance.h"
#include "core/registration/calibration.h"
#include "core/registration/registration.h"
#include "core/types/transform.h"

namespace surfinspect {
namespace {

using Key = std::pair<std::string, std::string>;  // measurement, view

PointCloud WithRayNoise(const PointCloud& clean, double sigma, uint64_t seed) {
  if (sigma <= 0) return clean;
  PointCloud out = clean;
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> g(0.0f, float(sigma));
  for (auto& p : out.points)
    if (PointCloud::IsValid(p)) p += g(rng) * p.normalized();
  return out;
}

class AcceptanceSimulation : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    cell_ = new DemoCell(MakeDemoCell());
    scene_ = new AcceptanceScene(MakeDemoAcceptance(*cell_));
    auto index = MeshIndex::Build(cell_->gauge);
    ASSERT_TRUE(index.ok()) << index.status();
    gauge_ = index->release();
    scans_ = new std::map<Key, PointCloud>;
    gauge_scans_ = new std::vector<PointCloud>;
    const Artefacts& a = scene_->artefacts;
    std::vector<Key> keys;
    for (const auto& m : a.spheres) keys.emplace_back(m.name, m.at.view);
    for (const auto& b : a.ball_bar)
      keys.insert(keys.end(), {{b.name, b.a.view}, {b.name, b.b.view}});
    for (const auto& p : a.plates) keys.emplace_back(p.name, p.at.view);
    for (const Key& k : keys) {
      if (scans_->count(k)) continue;
      auto v = ViewIndex(*cell_, k.second);
      ASSERT_TRUE(v.ok());
      auto s = SimulateAcceptanceScan(*cell_, *scene_, k.first,
                                      cell_->viewpoints[*v].world_from_sensor, ScanOptions{});
      ASSERT_TRUE(s.ok()) << s.status();
      (*scans_)[k] = std::move(s->cloud_in_sensor);
    }
    for (std::size_t v = 0; v < cell_->viewpoints.size(); ++v) {
      auto s = SimulateDemoGaugeScan(*cell_, v, ScanOptions{});
      ASSERT_TRUE(s.ok());
      gauge_scans_->push_back(std::move(s->cloud_in_sensor));
    }
  }
  static void TearDownTestSuite() {
    delete gauge_scans_;
    delete scans_;
    delete gauge_;
    delete scene_;
    delete cell_;
  }

  struct Run {
    std::map<std::string, Eigen::Isometry3d> world_from_sensor;  // used to register
    std::map<std::string, ViewCalibrationUncertainty> views;
    double noise = 0;
    uint64_t seed = 1;
  };

  // Perfect calibrations: the true poses, zero covariance.
  static Run Perfect() {
    Run r;
    for (const auto& vp : cell_->viewpoints) {
      r.world_from_sensor[vp.name] = vp.world_from_sensor;
      r.views[vp.name] = {vp.world_from_gauge, PoseCovariance::Zero()};
    }
    return r;
  }

  // Calibrates every viewpoint on its gauge scan with `noise` (the pose
  // starts 0.3 mm / 0.1 deg off, so no coarse search is needed).
  static Run Calibrated(double noise, uint64_t seed) {
    Run r;
    r.noise = noise;
    r.seed = seed;
    for (std::size_t v = 0; v < cell_->viewpoints.size(); ++v) {
      const DemoViewpoint& vp = cell_->viewpoints[v];
      Eigen::Isometry3d start = vp.world_from_sensor;
      start.translate(Eigen::Vector3d(0.3, -0.3, 0.3));
      start.rotate(Eigen::AngleAxisd(0.1 * M_PI / 180, Eigen::Vector3d::UnitY()));
      CalibrationSettings s;
      s.coarse_search_deg = 0;
      auto cal =
          CalibrateViewpoint(*gauge_, vp.world_from_gauge,
                             WithRayNoise((*gauge_scans_)[v], noise, seed * 100 + v), start, s);
      EXPECT_TRUE(cal.ok()) << cal.status();
      if (!cal.ok()) continue;
      r.world_from_sensor[vp.name] = cal->world_from_sensor;
      r.views[vp.name] = {vp.world_from_gauge, cal->covariance};
    }
    return r;
  }

  // The scan of (name, view) with the run's noise, filtered and registered
  // through `world_from_sensor`.
  static absl::StatusOr<PointCloud> WorldCloud(const Run& run, const std::string& name,
                                               const std::string& view,
                                               const Eigen::Isometry3d& world_from_sensor) {
    const auto it = scans_->find({name, view});
    if (it == scans_->end()) return absl::NotFoundError(name + "/" + view);
    const uint64_t salt = std::hash<std::string>{}(name + view) % 100000;
    std::vector<ViewScan> views{
        {view, WithRayNoise(it->second, run.noise, run.seed * 100000 + salt), world_from_sensor}};
    if (auto st = FilterViews(views, LinkClusteringSettings{}); !st.ok()) return st;
    auto merged = RegisterToWorld(views);
    if (!merged.ok()) return merged.status();
    return merged->cloud_in_world;
  }

  static absl::StatusOr<AcceptanceResult> Accept(const Run& run, const Artefacts& artefacts) {
    const WorldScanFn scan = [&](const std::string& name, const std::string& view) {
      return WorldCloud(run, name, view, run.world_from_sensor.at(view));
    };
    return RunAcceptance(artefacts, run.views, scan);
  }

  static const Eigen::Isometry3d& TruePose(const std::string& view) {
    return cell_->viewpoints[*ViewIndex(*cell_, view)].world_from_sensor;
  }

  // PF and F as the guideline defines them, from the true geometry: the
  // trimmed range of each point's residual from the TRUE sphere / plate
  // (noise and planted form error included, fit error excluded).
  static double TruePf(const Run& run, const SphereMeasurement& m) {
    const Eigen::Vector3d c = scene_->objects.at(m.name).true_centres_world[0];
    const double r = 0.5 * scene_->true_sphere_diameter_mm;
    std::vector<double> res;
    WorldCloud(run, m.name, m.at.view, TruePose(m.at.view))
        ->ForEachValid([&](std::size_t, const Eigen::Vector3f& p) {
          const double d = (p.cast<double>() - c).norm() - r;
          if (std::abs(d) <= 0.5) res.push_back(d);
        });
    std::size_t lo, hi, out;
    return TrimmedRange(res, scene_->artefacts.outlier_share, &lo, &hi, &out);
  }
  static double TrueF(const Run& run, const PlateMeasurement& m) {
    const Eigen::Isometry3d& pose = scene_->objects.at(m.name).world_from_object;
    const Eigen::Vector3d n = pose.linear().col(2), c = pose.translation();
    std::vector<double> res;
    WorldCloud(run, m.name, m.at.view, TruePose(m.at.view))
        ->ForEachValid([&](std::size_t, const Eigen::Vector3f& p) {
          const Eigen::Vector3d d = p.cast<double>() - c;
          const double h = d.dot(n);
          if (std::abs(h) <= 0.5 && (d - h * n).norm() <= m.radius_mm) res.push_back(h);
        });
    std::size_t lo, hi, out;
    return TrimmedRange(res, scene_->artefacts.outlier_share, &lo, &hi, &out);
  }

  static double PsTruth() {
    return scene_->true_sphere_diameter_mm - scene_->artefacts.sphere_diameter_mm;
  }
  static double SdTruth() { return scene_->true_length_mm - scene_->artefacts.ball_bar_length_mm; }
  // Artefacts with only the cross-view ball-bar positions (one cheap run).
  static Artefacts CrossViewOnly() {
    Artefacts a = scene_->artefacts;
    std::vector<BallBarPosition> cross;
    for (const auto& b : a.ball_bar)
      if (b.cross_view()) cross.push_back(b);
    a.ball_bar = cross;
    return a;
  }

  static DemoCell* cell_;
  static AcceptanceScene* scene_;
  static MeshIndex* gauge_;
  static std::map<Key, PointCloud>* scans_;
  static std::vector<PointCloud>* gauge_scans_;
};
DemoCell* AcceptanceSimulation::cell_ = nullptr;
AcceptanceScene* AcceptanceSimulation::scene_ = nullptr;
MeshIndex* AcceptanceSimulation::gauge_ = nullptr;
std::map<Key, PointCloud>* AcceptanceSimulation::scans_ = nullptr;
std::vector<PointCloud>* AcceptanceSimulation::gauge_scans_ = nullptr;

// Whether a sphere is seen whole in a scan: some of its points, none on the
// image's border pixels.
bool SeenWhole(const PointCloud& scan_in_sensor, const Eigen::Isometry3d& world_from_sensor,
               const Eigen::Vector3d& centre, double r) {
  bool any = false, cut = false;
  for (std::size_t i = 0; i < scan_in_sensor.size(); ++i) {
    const Eigen::Vector3f& p = scan_in_sensor.points[i];
    if (!PointCloud::IsValid(p) || (world_from_sensor * p.cast<double>() - centre).norm() > r + 1)
      continue;
    any = true;
    const std::size_t row = i / scan_in_sensor.width, col = i % scan_in_sensor.width;
    cut = cut || row == 0 || col == 0 || row + 1 == scan_in_sensor.height ||
          col + 1 == scan_in_sensor.width;
  }
  return any && !cut;
}

TEST_F(AcceptanceSimulation, ArtefactsSpanTheVolumeAndFourPositionsNeedTwoViews) {
  const Artefacts& a = scene_->artefacts;
  EXPECT_GE(a.ball_bar.size(), 7u);
  std::set<std::string> views;
  int cross = 0;
  const double r = 0.5 * a.ball_bar_sphere_diameter_mm;
  for (const auto& b : a.ball_bar) {
    cross += b.cross_view();
    views.insert(b.a.view);
    views.insert(b.b.view);
    const auto& centres = scene_->objects.at(b.name).true_centres_world;
    // Each sphere whole in its own view; at a cross-view position, sphere b
    // not whole in a's view (and a not whole in b's): no view holds both.
    EXPECT_TRUE(SeenWhole((*scans_)[{b.name, b.a.view}], TruePose(b.a.view), centres[0], r))
        << b.name;
    EXPECT_TRUE(SeenWhole((*scans_)[{b.name, b.b.view}], TruePose(b.b.view), centres[1], r))
        << b.name;
    if (!b.cross_view()) continue;
    EXPECT_FALSE(SeenWhole((*scans_)[{b.name, b.a.view}], TruePose(b.a.view), centres[1], r))
        << b.name;
    EXPECT_FALSE(SeenWhole((*scans_)[{b.name, b.b.view}], TruePose(b.b.view), centres[0], r))
        << b.name;
    // And no third view sees both whole (ray-cast here: cross-view scans only).
    for (const auto& vp : cell_->viewpoints) {
      if (vp.name == b.a.view || vp.name == b.b.view) continue;
      auto s = SimulateAcceptanceScan(*cell_, *scene_, b.name, vp.world_from_sensor, ScanOptions{});
      ASSERT_TRUE(s.ok());
      EXPECT_FALSE(SeenWhole(s->cloud_in_sensor, vp.world_from_sensor, centres[0], r) &&
                   SeenWhole(s->cloud_in_sensor, vp.world_from_sensor, centres[1], r))
          << b.name << " whole in " << vp.name;
    }
  }
  EXPECT_EQ(cross, 4);
  EXPECT_EQ(views.size(), 5u);
}

TEST_F(AcceptanceSimulation, NoiseFreeFiguresComeBackWithin2um) {
  auto r = Accept(Perfect(), scene_->artefacts);
  ASSERT_TRUE(r.ok()) << r.status();
  for (const auto& [name, e] : r->spheres) {
    EXPECT_NEAR(e.pf_mm, 0.0, 0.002) << name;
    EXPECT_NEAR(e.ps_mm, PsTruth(), 0.002) << name;
  }
  for (const auto& s : r->sd) EXPECT_NEAR(s.spacing.sd_mm, SdTruth(), 0.002) << s.position.name;
  for (const auto& [name, f] : r->plates)
    EXPECT_NEAR(f.f_mm, scene_->true_flatness_mm, 0.002) << name;
  EXPECT_TRUE(r->pass);
}

TEST_F(AcceptanceSimulation, NoisyFiguresComeBackWithinTheirUncertainty) {
  const Run run = Calibrated(0.015, 1);
  auto r = Accept(run, scene_->artefacts);
  ASSERT_TRUE(r.ok()) << r.status();
  for (std::size_t k = 0; k < r->spheres.size(); ++k) {
    const auto& [name, e] = r->spheres[k];
    std::printf("  %s PS %+.4f (truth %+.4f, U %.4f)  PF %.4f (U %.4f, rms %.4f)\n", name.c_str(),
                e.ps_mm, PsTruth(), 2 * e.u_ps_mm, e.pf_mm, 2 * e.u_pf_mm, e.fit.rms);
    EXPECT_LE(std::abs(e.ps_mm - PsTruth()), 2 * std::hypot(e.u_ps_mm, 0.0002)) << name;
    const double pf_truth = TruePf(run, scene_->artefacts.spheres[k]);
    std::printf("    PF truth %.4f: off by %+.4f\n", pf_truth, e.pf_mm - pf_truth);
    EXPECT_LE(std::abs(e.pf_mm - pf_truth), 2 * e.u_pf_mm) << name;
  }
  for (std::size_t k = 0; k < r->plates.size(); ++k) {
    const Flatness& f = r->plates[k].second;
    const double f_truth = TrueF(run, scene_->artefacts.plates[k]);
    std::printf("  %s F %.4f (truth %.4f, U %.4f)\n", r->plates[k].first.c_str(), f.f_mm, f_truth,
                2 * f.u_f_mm);
    EXPECT_LE(std::abs(f.f_mm - f_truth), 2 * std::hypot(f.u_f_mm, 0.0002));
  }
  for (const auto& s : r->sd) {
    std::printf("  %s SD %+.4f (truth %+.4f, U %.4f = 2 x [fit %.4f, cal %.4f])\n",
                s.position.name.c_str(), s.spacing.sd_mm, SdTruth(), 2 * s.spacing.u_sd_mm,
                s.spacing.u_fit_mm, s.spacing.u_calibration_mm);
    EXPECT_LE(std::abs(s.spacing.sd_mm - SdTruth()), 2 * s.spacing.u_sd_mm) << s.position.name;
  }
  EXPECT_TRUE(r->pass);
}

TEST_F(AcceptanceSimulation, ViewpointCalibrated30umOffFailsSDExactlyWhereItIsUsed) {
  Run run = Perfect();
  const Eigen::Vector3d along_x = cell_->world_from_part.linear() * Eigen::Vector3d::UnitX();
  run.world_from_sensor["v1"].pretranslate(0.030 * along_x);
  auto r = Accept(run, scene_->artefacts);
  ASSERT_TRUE(r.ok()) << r.status();
  for (const auto& s : r->sd) {
    // A rigid offset cannot change a length seen from one view: only
    // cross-view positions with a sphere from v1 see it.
    const bool uses_v1 =
        s.position.cross_view() && (s.position.a.view == "v1" || s.position.b.view == "v1");
    EXPECT_EQ(s.pass, !uses_v1) << s.position.name << " SD " << s.spacing.sd_mm;
  }
  EXPECT_TRUE(r->pf.pass && r->ps.pass && r->f.pass);  // form and size do not see it
  EXPECT_FALSE(r->pass);
}

TEST_F(AcceptanceSimulation, CrossViewSDErrorsFallWithin3SigmaOver20SeededCells) {
  const Artefacts cross = CrossViewOnly();
  int n = 0, within = 0;
  double sum_z2 = 0, max_z = 0;
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    auto r = Accept(Calibrated(0.015, seed), cross);
    ASSERT_TRUE(r.ok()) << r.status();
    for (const auto& s : r->sd) {
      // The simulated bar's length is exact: the prediction for the error is
      // the fits' and the calibrations' σ, without the certificate's u.
      const double u = std::hypot(s.spacing.u_fit_mm, s.spacing.u_calibration_mm);
      const double z = (s.spacing.sd_mm - SdTruth()) / u;
      ++n;
      within += std::abs(z) <= 3;
      sum_z2 += z * z;
      max_z = std::max(max_z, std::abs(z));
    }
  }
  std::printf(
      "  cross-view SD error / combined sigma over %d positions: %d within 3, rms %.2f, max %.2f\n",
      n, within, std::sqrt(sum_z2 / n), max_z);
  EXPECT_EQ(n, 80);
  EXPECT_GE(within, 0.95 * n);
}

}  // namespace
}  // namespace surfinspect
