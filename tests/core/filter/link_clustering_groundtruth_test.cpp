// Ground truth for the link-clustering filter: simulated scans of the demo
// part from its five viewpoints, with sensor noise, ~0.3% pulses, stripes at
// the steps and planted dents/bumps, scored per pixel label.
#include <gtest/gtest.h>

#include <cstring>
#include <iostream>

#include "core/filter/link_clustering.h"
#include "core/simulation/demo_cell.h"
#include "core/simulation/scan_simulator.h"

namespace surfinspect {
namespace {

struct Score {
  std::size_t pulses = 0, pulses_removed = 0;
  std::size_t stripes = 0, stripes_removed = 0;
  std::size_t good = 0, good_kept = 0;
  std::size_t defect = 0, defect_kept = 0;
  void Add(const Score& o) {
    pulses += o.pulses, pulses_removed += o.pulses_removed;
    stripes += o.stripes, stripes_removed += o.stripes_removed;
    good += o.good, good_kept += o.good_kept;
    defect += o.defect, defect_kept += o.defect_kept;
  }
  static double Ratio(std::size_t a, std::size_t b) { return b ? double(a) / b : 1.0; }
  double pulse_recall() const { return Ratio(pulses_removed, pulses); }
  double stripe_recall() const { return Ratio(stripes_removed, stripes); }
  double good_kept_ratio() const { return Ratio(good_kept, good); }
  double defect_kept_ratio() const { return Ratio(defect_kept, defect); }
};

std::ostream& operator<<(std::ostream& os, const Score& s) {
  return os << "pulses " << s.pulses_removed << "/" << s.pulses << " removed ("
            << 100 * s.pulse_recall() << "%), stripes " << s.stripes_removed << "/" << s.stripes
            << " (" << 100 * s.stripe_recall() << "%), good kept " << s.good_kept << "/" << s.good
            << " (" << 100 * s.good_kept_ratio() << "%), defect kept " << s.defect_kept << "/"
            << s.defect << " (" << 100 * s.defect_kept_ratio() << "%)";
}

// Defects planted where the clean scan sees the part: the pixel's point,
// taken back to the part frame, lies on the CAD surface.
std::vector<SurfaceDefect> PlantDefects(const DemoCell& cell, const DemoViewpoint& vp) {
  auto clean =
      SimulateScan(cell.part, cell.world_from_part, vp.world_from_sensor, cell.intrinsics, {});
  EXPECT_TRUE(clean.ok());
  const Eigen::Isometry3d part_from_sensor = cell.world_from_part.inverse() * vp.world_from_sensor;
  // (row, col, depth mm, radius mm): depths 0.05-0.5 mm and radii 3-8 mm,
  // one of them a bump.
  const double plan[5][4] = {{384, 512, 0.05, 3.0},
                             {250, 300, 0.5, 3.0},
                             {520, 700, 0.2, 8.0},
                             {300, 760, 0.35, 5.0},
                             {480, 260, -0.3, 6.0}};
  std::vector<SurfaceDefect> defects;
  for (const auto& p : plan) {
    const std::size_t i = std::size_t(p[0]) * cell.intrinsics.width + std::size_t(p[1]);
    const Eigen::Vector3f& q = clean->cloud_in_sensor.points[i];
    if (!PointCloud::IsValid(q)) continue;
    SurfaceDefect d;
    d.center_in_part = part_from_sensor * q.cast<double>();
    d.depth_mm = p[2];
    d.radius_mm = p[3];
    defects.push_back(d);
  }
  return defects;
}

Score ScoreFilter(const SimulatedScan& scan, const LinkClusteringResult& r) {
  Score s;
  for (std::size_t i = 0; i < scan.labels.size(); ++i) {
    const bool kept = r.kept_mask[i] != 0;
    switch (scan.labels[i]) {
      case PixelLabel::kPulse:
        ++s.pulses, s.pulses_removed += !kept;
        break;
      case PixelLabel::kStripe:
        ++s.stripes, s.stripes_removed += !kept;
        break;
      case PixelLabel::kGood:
        ++s.good, s.good_kept += kept;
        break;
      case PixelLabel::kDefect:
        ++s.defect, s.defect_kept += kept;
        break;
      case PixelLabel::kNoData:
        break;
    }
  }
  return s;
}

// The demo part from its five viewpoints with noise ~0.015 mm, 0.3% pulses,
// stripes and five planted defects each, simulated once for all tests.
class LinkClusteringGroundTruth : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const DemoCell cell = MakeDemoCell();
    scans_ = new std::vector<SimulatedScan>;
    for (std::size_t v = 0; v < cell.viewpoints.size(); ++v) {
      const DemoViewpoint& vp = cell.viewpoints[v];
      ScanOptions opt;
      opt.noise_sigma_mm = 0.015;
      opt.pulse_fraction = 0.003;
      opt.stripes = true;
      opt.defects = PlantDefects(cell, vp);
      opt.seed = 100 + v;
      auto scan =
          SimulateScan(cell.part, cell.world_from_part, vp.world_from_sensor, cell.intrinsics, opt);
      ASSERT_TRUE(scan.ok()) << scan.status();
      scans_->push_back(*std::move(scan));
    }
  }
  static void TearDownTestSuite() { delete scans_; }

  // Filters every scan; checks the per-scan sanity and the kept bits.
  static Score FilterAll(const LinkClusteringSettings& settings) {
    Score total;
    LinkClusteringResult r;  // reused across views, as the pipeline does
    for (std::size_t v = 0; v < scans_->size(); ++v) {
      const SimulatedScan& scan = (*scans_)[v];
      EXPECT_TRUE(ClusterLinksInto(scan.cloud_in_sensor, settings, r).ok());
      const Score s = ScoreFilter(scan, r);
      std::cout << "v" << v + 1 << ": " << s << ", clusters " << r.clusters.size() << "\n";
      EXPECT_GT(s.pulses, 300u);
      EXPECT_GT(s.stripes, 100u);
      EXPECT_GT(s.defect, 1000u);
      total.Add(s);

      // Kept coordinates are bit-identical, removed ones NaN, the grid stays.
      auto out = ApplyFilter(scan.cloud_in_sensor, r);
      EXPECT_TRUE(out.ok());
      if (!out.ok()) continue;
      EXPECT_EQ(out->width, scan.cloud_in_sensor.width);
      EXPECT_EQ(out->height, scan.cloud_in_sensor.height);
      std::size_t kept_valid = 0, bad = 0;
      for (std::size_t i = 0; i < out->size(); ++i) {
        if (r.kept_mask[i]) {
          ++kept_valid;
          bad += std::memcmp(out->points[i].data(), scan.cloud_in_sensor.points[i].data(), 12) != 0;
        } else {
          bad += PointCloud::IsValid(out->points[i]);
        }
      }
      EXPECT_EQ(bad, 0u);
      EXPECT_EQ(kept_valid, r.kept);
    }
    std::cout << "all: " << total << "\n";
    return total;
  }

  static std::vector<SimulatedScan>* scans_;
};
std::vector<SimulatedScan>* LinkClusteringGroundTruth::scans_ = nullptr;

// The targets for scans that feed an error map: >= 99% of pulses and 95% of
// stripe pixels removed, >= 99% of good and 99.9% of dent points kept.
TEST_F(LinkClusteringGroundTruth, InspectionPresetMeetsItsTargets) {
  const Score total = FilterAll(LinkClusteringSettings::ForInspection());
  EXPECT_GE(total.pulse_recall(), 0.99) << total;
  EXPECT_GE(total.stripe_recall(), 0.95) << total;
  EXPECT_GE(total.good_kept_ratio(), 0.99) << total;
  EXPECT_GE(total.defect_kept_ratio(), 0.999) << total;
}

// The paper's defaults (0.5 mm) remove outliers more thoroughly, as
// calibration wants, at the price of dent points on steep walls: measured
// 99.6% kept, below the 99.9% an error map needs (hence ForInspection()).
TEST_F(LinkClusteringGroundTruth, DefaultsRemoveOutliersMoreThoroughly) {
  const Score defaults = FilterAll(LinkClusteringSettings{});
  const Score inspection = FilterAll(LinkClusteringSettings::ForInspection());
  EXPECT_GE(defaults.pulse_recall(), 0.99) << defaults;
  EXPECT_GE(defaults.stripe_recall(), 0.995) << defaults;
  EXPECT_GE(defaults.good_kept_ratio(), 0.99) << defaults;
  EXPECT_GT(defaults.stripe_recall(), inspection.stripe_recall());
  EXPECT_LT(defaults.defect_kept_ratio(), inspection.defect_kept_ratio());
}

}  // namespace
}  // namespace surfinspect
