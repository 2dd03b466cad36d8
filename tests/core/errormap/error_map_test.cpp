// Covers core/errormap/error_map.cpp (ComputeErrorMap, AutoColorRange); the
// files made from an error map are tested in tests/core/report/.
#include "core/errormap/error_map.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "core/pipeline/inspection_report.h"
#include "core/report/error_map_output.h"
#include "core/report/error_map_png.h"
#include "core/simulation/demo_cell.h"
#include "core/simulation/scan_simulator.h"
#include "core/types/transform.h"
#include "tests/support/temp_dir.h"
#include "tests/support/test_meshes.h"

namespace surfinspect {
namespace {

using Eigen::Vector3d;
using Eigen::Vector3f;
using testing::TempDir;

// Points above the plane's interior with heights `z` (NaN entries become NaN pixels).
PointCloud Above(const std::vector<double>& z, uint64_t seed = 1) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(10, 90);
  std::vector<Vector3f> pts;
  for (double h : z)
    pts.push_back(std::isnan(h) ? Vector3f::Constant(NAN)
                                : Vector3f(u(rng), u(rng), static_cast<float>(h)));
  return PointCloud::Unorganized(pts);
}

// NumPy's "linear" percentile on a fully sorted copy: the oracle for the
// nth_element version.
double SortedPercentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  const double pos = q * (v.size() - 1);
  const auto lo = static_cast<std::size_t>(pos);
  return lo + 1 < v.size() ? v[lo] + (pos - lo) * (v[lo + 1] - v[lo]) : v[lo];
}

TEST(ErrorMap, DeviationsStatisticsHistogramAndVerdictOnAPlane) {
  auto index = testing::IndexOf(testing::FlatSquare());
  ASSERT_TRUE(index);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g(0.01, 0.05);
  std::vector<double> z;
  for (int i = 0; i < 5001; ++i) z.push_back(static_cast<float>(g(rng)));  // float-exact heights
  z.insert(z.end(), {NAN, NAN, 9.0, -7.5});  // two NaN pixels, two beyond max_distance
  const PointCloud cloud = Above(z);
  ErrorMapSettings s;
  s.tolerance_mm = 0.08;
  s.max_distance_mm = 5;
  auto r = ComputeErrorMap(*index, cloud, Eigen::Isometry3d::Identity(), s);
  ASSERT_TRUE(r.ok()) << r.status();

  std::vector<double> matched;
  std::size_t within = 0, above = 0, below = 0;
  for (std::size_t i = 0; i < 5001; ++i) {
    EXPECT_EQ(r->deviation_mm[i], static_cast<float>(z[i])) << "exact signed distance to the plane";
    EXPECT_EQ(r->closest_point[i].z(), 0.f);
    EXPECT_EQ(r->closest_point[i].head<2>(), cloud.points[i].head<2>());
    matched.push_back(z[i]);
    within += std::abs(z[i]) <= 0.08;
    above += z[i] > 0.08;
    below += z[i] < -0.08;
  }
  for (std::size_t i = 5001; i < z.size(); ++i) {
    EXPECT_TRUE(std::isnan(r->deviation_mm[i]));
    EXPECT_EQ(r->triangle_id[i], UINT32_MAX);
  }
  const ErrorMapStats& st = r->stats;
  EXPECT_EQ(st.count, 5005u);
  EXPECT_EQ(st.valid, 5003u);
  EXPECT_EQ(st.matched, 5001u);
  double sum = 0, sum2 = 0;
  for (double d : matched) sum += d, sum2 += d * d;
  const double mean = sum / matched.size();
  double var = 0;
  for (double d : matched) var += (d - mean) * (d - mean);
  EXPECT_NEAR(st.mean_mm, mean, 1e-12);
  EXPECT_NEAR(st.rms_mm, std::sqrt(sum2 / matched.size()), 1e-12);
  EXPECT_NEAR(st.stddev_mm, std::sqrt(var / matched.size()), 1e-12);
  EXPECT_EQ(st.min_mm, *std::min_element(matched.begin(), matched.end()));
  EXPECT_EQ(st.max_mm, *std::max_element(matched.begin(), matched.end()));
  EXPECT_NEAR(st.p1_mm, SortedPercentile(matched, 0.01), 1e-12);
  EXPECT_NEAR(st.p5_mm, SortedPercentile(matched, 0.05), 1e-12);
  EXPECT_NEAR(st.p50_mm, SortedPercentile(matched, 0.50), 1e-12);
  EXPECT_NEAR(st.p95_mm, SortedPercentile(matched, 0.95), 1e-12);
  EXPECT_NEAR(st.p99_mm, SortedPercentile(matched, 0.99), 1e-12);

  EXPECT_EQ(r->verdict.within, within);
  EXPECT_EQ(r->verdict.above, above);
  EXPECT_EQ(r->verdict.below, below);
  EXPECT_GT(above + below, 0u);
  EXPECT_FALSE(r->verdict.pass) << "strict default: any point outside fails";
  EXPECT_NEAR(r->verdict.fraction_within, static_cast<double>(within) / 5001, 1e-15);

  // Histogram: auto range, every matched point in exactly its bin.
  const Histogram& h = r->histogram;
  EXPECT_EQ(r->color_range_mm, AutoColorRange(0.08, st.p1_mm, st.p99_mm));
  EXPECT_EQ(h.min_mm, -r->color_range_mm);
  EXPECT_EQ(h.counts.size(), 41u);
  std::vector<std::size_t> want(41, 0);
  std::size_t out_low = 0, out_high = 0;
  for (double d : matched) {
    const double k = std::floor((d - h.min_mm) / h.bin_width_mm());
    if (k < 0)
      ++out_low;
    else if (k >= 41)
      ++out_high;
    else
      ++want[static_cast<std::size_t>(k)];
  }
  EXPECT_EQ(h.counts, want);
  EXPECT_EQ(h.below_range, out_low);
  EXPECT_EQ(h.above_range, out_high);
}

TEST(ErrorMap, VerdictHonoursTheAllowedFraction) {
  auto index = testing::IndexOf(testing::FlatSquare());
  ASSERT_TRUE(index);
  std::vector<double> z(90, 0.05);
  z.insert(z.end(), 10, 0.3);  // 10% outside, all above
  const PointCloud cloud = Above(z);
  ErrorMapSettings s;
  s.tolerance_mm = 0.1;
  s.allowed_fraction_outside = 0.10;
  auto pass = ComputeErrorMap(*index, cloud, Eigen::Isometry3d::Identity(), s);
  ASSERT_TRUE(pass.ok());
  EXPECT_TRUE(pass->verdict.pass) << pass->verdict.reason;
  EXPECT_EQ(pass->verdict.above, 10u);
  EXPECT_NE(pass->verdict.reason.find("pass"), std::string::npos);
  s.allowed_fraction_outside = 0.09;
  auto fail = ComputeErrorMap(*index, cloud, Eigen::Isometry3d::Identity(), s);
  ASSERT_TRUE(fail.ok());
  EXPECT_FALSE(fail->verdict.pass);
  EXPECT_NEAR(fail->verdict.fraction_outside, 0.1, 1e-12);
}

TEST(ErrorMap, NothingMatchedFailsWithNaNStatistics) {
  auto index = testing::IndexOf(testing::FlatSquare());
  ASSERT_TRUE(index);
  for (const PointCloud& cloud : {PointCloud{}, Above({50.0, NAN})}) {
    auto r = ComputeErrorMap(*index, cloud, Eigen::Isometry3d::Identity(), {});
    ASSERT_TRUE(r.ok()) << r.status();
    EXPECT_EQ(r->stats.matched, 0u);
    EXPECT_TRUE(std::isnan(r->stats.mean_mm));
    EXPECT_TRUE(std::isnan(r->stats.p50_mm));
    EXPECT_FALSE(r->verdict.pass);
    EXPECT_NE(r->verdict.reason.find("no point"), std::string::npos);
    const nlohmann::json j = ErrorMapReportJson(*r, {});
    EXPECT_TRUE(j["statistics"]["mean_mm"].is_null());
    EXPECT_EQ(j["tolerance"]["verdict"], "fail");
  }
}

TEST(ErrorMap, WorldFromPartIsApplied) {
  auto index = testing::IndexOf(testing::FlatSquare());
  ASSERT_TRUE(index);
  const PointCloud in_part = Above({0.2, -0.1, 0.05, 0.0});
  const Eigen::Isometry3d world_from_part =
      Eigen::Translation3d(600, 100, 5) * Eigen::AngleAxisd(0.3, Vector3d(1, 2, 3).normalized());
  const PointCloud in_world = TransformCloud(in_part, world_from_part);
  auto r = ComputeErrorMap(*index, in_world, world_from_part, {});
  ASSERT_TRUE(r.ok());
  const std::vector<float> want = {0.2f, -0.1f, 0.05f, 0.0f};
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(r->deviation_mm[i], want[i], 1e-4);  // float round trip
}

TEST(ErrorMap, SplitComponentsAreThePointMinusClosestVector) {
  auto index = testing::IndexOf(testing::Box(Vector3d::Zero(), Vector3d::Constant(10)));
  ASSERT_TRUE(index);
  // Above a face, beyond an edge, beyond a corner, inside.
  const PointCloud cloud = PointCloud::Unorganized(
      {Vector3f(5, 5, 10.5f), Vector3f(11, 5, 11), Vector3f(-1, -2, 12), Vector3f(5, 5, 9)});
  ErrorMapSettings s;
  s.split_components = true;
  auto r = ComputeErrorMap(*index, cloud, Eigen::Isometry3d::Identity(), s);
  ASSERT_TRUE(r.ok());
  ASSERT_EQ(r->deviation_xyz_mm.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    const Vector3f diff = cloud.points[i] - r->closest_point[i];
    EXPECT_TRUE(r->deviation_xyz_mm[i].isApprox(diff, 1e-6f)) << i;
    EXPECT_NEAR(r->deviation_xyz_mm[i].norm(), std::abs(r->deviation_mm[i]), 1e-5);
  }
  EXPECT_NEAR(r->normal_deviation_mm[0], 0.5, 1e-6) << "inside a face: along the normal";
  EXPECT_NEAR(r->deviation_mm[1], std::sqrt(2.0), 1e-6) << "beyond an edge: the distance";
  EXPECT_NEAR(std::abs(r->normal_deviation_mm[1]), 1.0, 1e-6) << "point-to-plane of one face";
  EXPECT_NEAR(r->deviation_mm[2], std::sqrt(1.0 + 4 + 4), 1e-6);
  EXPECT_NEAR(r->deviation_mm[3], -1.0, 1e-6);
  EXPECT_NEAR(r->component_stats[2].max_mm, 2.0, 1e-6);  // z of the corner point
  EXPECT_TRUE(ErrorMapReportJson(*r, s).contains("components"));
  // Without the split nothing is filled.
  auto plain = ComputeErrorMap(*index, cloud, Eigen::Isometry3d::Identity(), {});
  ASSERT_TRUE(plain.ok());
  EXPECT_TRUE(plain->deviation_xyz_mm.empty());
  EXPECT_FALSE(ErrorMapReportJson(*plain, {}).contains("components"));
}

TEST(ErrorMap, ThreadCountDoesNotChangeAnything) {
  auto index = testing::IndexOf(testing::Torus(40, 12, 64, 32));
  ASSERT_TRUE(index);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<float> u(-55, 55);
  std::vector<Vector3f> pts;
  for (int i = 0; i < 20000; ++i) pts.emplace_back(u(rng), u(rng), u(rng) / 4);
  const PointCloud cloud = PointCloud::Unorganized(pts);
  ErrorMapSettings s;
  s.threads = 1;
  auto one = ComputeErrorMap(*index, cloud, Eigen::Isometry3d::Identity(), s);
  s.threads = 2;
  auto two = ComputeErrorMap(*index, cloud, Eigen::Isometry3d::Identity(), s);
  ASSERT_TRUE(one.ok() && two.ok());
  ASSERT_EQ(0, std::memcmp(one->deviation_mm.data(), two->deviation_mm.data(),
                           pts.size() * sizeof(float)));
  EXPECT_EQ(one->triangle_id, two->triangle_id);
  EXPECT_EQ(one->stats.rms_mm, two->stats.rms_mm);
  EXPECT_EQ(one->stats.p99_mm, two->stats.p99_mm);
  EXPECT_EQ(one->histogram.counts, two->histogram.counts);
}

TEST(ErrorMap, RejectsBadSettingsAndHonoursCancel) {
  auto index = testing::IndexOf(testing::FlatSquare());
  ASSERT_TRUE(index);
  const PointCloud cloud = Above(std::vector<double>(3000, 0.01));
  auto code = [&](const ErrorMapSettings& s) {
    return ComputeErrorMap(*index, cloud, Eigen::Isometry3d::Identity(), s).status().code();
  };
  const auto kBad = absl::StatusCode::kInvalidArgument;
  ErrorMapSettings s;
  s.tolerance_mm = 0;
  EXPECT_EQ(code(s), kBad);
  s.tolerance_mm = NAN;
  EXPECT_EQ(code(s), kBad);
  s = {};
  s.max_distance_mm = 0;
  EXPECT_EQ(code(s), kBad);
  s = {};
  s.allowed_fraction_outside = 1.5;
  EXPECT_EQ(code(s), kBad);
  s = {};
  s.histogram_bins = 0;
  EXPECT_EQ(code(s), kBad);
  s = {};
  s.histogram_range_mm = -1;
  EXPECT_EQ(code(s), kBad);
  s = {};
  s.threads = -1;
  EXPECT_EQ(code(s), kBad);
  Eigen::Isometry3d bad_pose = Eigen::Isometry3d::Identity();
  bad_pose(0, 3) = INFINITY;
  EXPECT_EQ(ComputeErrorMap(*index, cloud, bad_pose, {}).status().code(), kBad);
  // A malformed cloud: an infinite coordinate, a grid of the wrong size.
  PointCloud infinite = cloud;
  infinite.points[1234].y() = -INFINITY;
  const auto st = ComputeErrorMap(*index, infinite, Eigen::Isometry3d::Identity(), {}).status();
  EXPECT_EQ(st.code(), kBad);
  EXPECT_NE(st.message().find("point 1234 has an infinite coordinate"), std::string::npos) << st;
  PointCloud wrong = cloud;
  wrong.width = 7;
  wrong.height = 3;
  EXPECT_EQ(ComputeErrorMap(*index, wrong, Eigen::Isometry3d::Identity(), {}).status().code(),
            kBad);
  std::atomic<bool> cancel{true};
  EXPECT_EQ(
      ComputeErrorMap(*index, cloud, Eigen::Isometry3d::Identity(), {}, &cancel).status().code(),
      absl::StatusCode::kCancelled);
}

TEST(ErrorMap, AutoColorRangeRoundsUpToNiceNumbers) {
  EXPECT_DOUBLE_EQ(AutoColorRange(0.1, -0.05, 0.07), 0.2);
  EXPECT_DOUBLE_EQ(AutoColorRange(0.1, -0.25, 0.0), 0.25);
  EXPECT_DOUBLE_EQ(AutoColorRange(0.1, -0.33, 0.2), 0.5);
  EXPECT_DOUBLE_EQ(AutoColorRange(0.1, -1.2, 0.4), 2.0);
  EXPECT_DOUBLE_EQ(AutoColorRange(0.05, NAN, NAN), 0.1);
  EXPECT_DOUBLE_EQ(AutoColorRange(0.1, -0.1, 6.0), 10.0);
}

// On demo-part scans with planted dents, noise-free,
// the deviation at the dent centre is within 5 um of the planted depth.
TEST(ErrorMapDemo, DentCentreDeviationIsThePlantedDepth) {
  const DemoCell cell = MakeDemoCell();
  auto index = testing::IndexOf(cell.part);
  ASSERT_TRUE(index);
  const Bounds3 b = ComputeBounds(cell.part);
  struct Planted {
    double x, y, depth, radius;
  };
  for (const Planted& p :
       {Planted{-60, 5, 0.30, 6}, Planted{40, -12, 0.08, 4}, Planted{95, 0, -0.2, 7}}) {
    // The dent centre on the CAD ridge: the closest surface point below (x, y, top).
    const ClosestPoint top = index->Closest(Vector3d(p.x, p.y, b.max.z() + 5));
    ASSERT_TRUE(top.matched());
    ASSERT_GT(top.normal.z(), 0.99) << "on the top ridge";
    SurfaceDefect dent;
    dent.center_in_part = top.point;
    dent.depth_mm = p.depth;
    dent.radius_mm = p.radius;
    ScanOptions opt;  // noise-free
    opt.defects = {dent};
    const Vector3d centre_world = cell.world_from_part * top.point;
    const Vector3d up_world = cell.world_from_part.linear() * top.normal;
    const Eigen::Isometry3d world_from_sensor =
        LookAt(centre_world + 400 * up_world + Vector3d(7, 3, 0), centre_world);
    auto scan =
        SimulateScan(cell.part, cell.world_from_part, world_from_sensor, cell.intrinsics, opt);
    ASSERT_TRUE(scan.ok()) << scan.status();
    const PointCloud in_world = TransformCloud(scan->cloud_in_sensor, world_from_sensor);
    ErrorMapSettings s;
    s.tolerance_mm = 0.05;
    auto r = ComputeErrorMap(*index, in_world, cell.world_from_part, s);
    ASSERT_TRUE(r.ok()) << r.status();
    // The pixel whose measured point lies nearest the dent axis.
    const Eigen::Isometry3d part_from_world = cell.world_from_part.inverse();
    std::size_t best = SIZE_MAX;
    double best_r = INFINITY;
    for (std::size_t i = 0; i < in_world.size(); ++i) {
      if (!PointCloud::IsValid(in_world.points[i])) continue;
      const Vector3d q = part_from_world * in_world.points[i].cast<double>() - top.point;
      const double radial = (q - q.dot(top.normal) * top.normal).norm();
      if (radial < best_r) best_r = radial, best = i;
    }
    ASSERT_NE(best, SIZE_MAX);
    EXPECT_LT(best_r, 0.3);
    EXPECT_NEAR(r->deviation_mm[best], -p.depth, 0.005) << "dent at x " << p.x;
    // And across the whole dent the map follows the simulator's truth.
    std::size_t compared = 0;
    for (std::size_t i = 0; i < in_world.size(); ++i) {
      if (scan->labels[i] != PixelLabel::kDefect) continue;
      EXPECT_NEAR(r->deviation_mm[i], scan->true_deviation_mm[i], 1e-4) << i;  // seen: 2e-5 mm
      ++compared;
    }
    EXPECT_GT(compared, 100u);
  }
}

}  // namespace
}  // namespace surfinspect
