#include "core/simulation/scan_simulator.h"

#include <gtest/gtest.h>

#include <cstring>

#include "core/types/transform.h"

namespace surfinspect {
namespace {

// A square plate [-half, half]^2 at z = 0 (part frame), normal +z.
TriangleMesh Plate(float half) {
  TriangleMesh m;
  m.vertices = {{-half, -half, 0}, {half, -half, 0}, {half, half, 0}, {-half, half, 0}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

// Two plates at z = 0 (x < 0) and z = -20 (x >= 0): a step with a jump.
TriangleMesh Step() {
  TriangleMesh m;
  m.vertices = {{-100, -100, 0}, {0, -100, 0},     {0, 100, 0},     {-100, 100, 0},
                {0, -100, -20},  {100, -100, -20}, {100, 100, -20}, {0, 100, -20}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}};
  return m;
}

Eigen::Isometry3d Tilted(double deg_x, double deg_y, const Eigen::Vector3d& t) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = (Eigen::AngleAxisd(deg_x * M_PI / 180, Eigen::Vector3d::UnitX()) *
                Eigen::AngleAxisd(deg_y * M_PI / 180, Eigen::Vector3d::UnitY()))
                   .toRotationMatrix();
  p.translation() = t;
  return p;
}

const Eigen::Isometry3d kWorldFromPart = Tilted(4, -3, {50, -20, 10});
Eigen::Isometry3d SensorAbove(double height = 400) {
  const Eigen::Vector3d target = kWorldFromPart * Eigen::Vector3d(5, 3, 0);
  return LookAt(target + Eigen::Vector3d(30, -20, height), target);
}

TEST(ScanSimulator, PlanePointsLieOnPlaneAndFootprintIsAnalytic) {
  const float half = 60;
  ScanOptions opt;
  opt.noise_sigma_mm = 0.01;
  const Eigen::Isometry3d world_from_sensor = SensorAbove();
  auto scan = SimulateScan(Plate(half), kWorldFromPart, world_from_sensor, {}, opt);
  ASSERT_TRUE(scan.ok()) << scan.status();
  const SensorIntrinsics in;
  const Eigen::Isometry3d part_from_sensor = kWorldFromPart.inverse() * world_from_sensor;
  const double f = FocalLengthPixels(in);
  std::size_t mismatches = 0, hits = 0;
  for (uint32_t row = 0; row < in.height; ++row)
    for (uint32_t col = 0; col < in.width; ++col) {
      const std::size_t i = std::size_t{row} * in.width + col;
      // Analytic footprint: intersect the pixel ray with z = 0 in the part frame.
      const Eigen::Vector3d ray =
          part_from_sensor.linear() *
          Eigen::Vector3d((col + 0.5 - in.width / 2.0) / f, (row + 0.5 - in.height / 2.0) / f, 1);
      const Eigen::Vector3d o = part_from_sensor.translation();
      const Eigen::Vector3d x = o + (-o.z() / ray.z()) * ray;
      const bool inside = std::abs(x.x()) < half && std::abs(x.y()) < half;
      const bool near_edge =
          std::abs(std::abs(x.x()) - half) < 1e-3 || std::abs(std::abs(x.y()) - half) < 1e-3;
      const bool valid = PointCloud::IsValid(scan->cloud_in_sensor.points[i]);
      if (valid != inside && !near_edge) ++mismatches;
      if (!valid) continue;
      ++hits;
      const Eigen::Vector3d p_part =
          part_from_sensor * scan->cloud_in_sensor.points[i].cast<double>();
      ASSERT_LT(std::abs(p_part.z()), 6 * 0.01 / std::abs(ray.normalized().z()) + 1e-4) << i;
      EXPECT_EQ(scan->labels[i], PixelLabel::kGood);
    }
  EXPECT_EQ(mismatches, 0u);
  EXPECT_GT(hits, 100000u);
  EXPECT_EQ(hits, scan->hits);
}

TEST(ScanSimulator, PulsesAreExactlyTheLabelledPixelsAndDisplacedAlongTheRay) {
  ScanOptions clean;
  ScanOptions pulsed;
  pulsed.pulse_fraction = 0.01;
  pulsed.seed = 9;
  const auto ws = SensorAbove();
  auto a = SimulateScan(Plate(80), kWorldFromPart, ws, {}, clean);
  auto b = SimulateScan(Plate(80), kWorldFromPart, ws, {}, pulsed);
  ASSERT_TRUE(a.ok() && b.ok());
  std::size_t pulses = 0;
  for (std::size_t i = 0; i < a->labels.size(); ++i) {
    const Eigen::Vector3f& p = a->cloud_in_sensor.points[i];
    const Eigen::Vector3f& q = b->cloud_in_sensor.points[i];
    if (b->labels[i] != PixelLabel::kPulse) {
      ASSERT_EQ(PointCloud::IsValid(p), PointCloud::IsValid(q));
      if (PointCloud::IsValid(p)) {
        ASSERT_EQ(0, std::memcmp(p.data(), q.data(), 12)) << i;
      }
      continue;
    }
    ++pulses;
    ASSERT_TRUE(PointCloud::IsValid(p) && PointCloud::IsValid(q));
    const double shift = q.cast<double>().norm() - p.cast<double>().norm();
    EXPECT_GE(std::abs(shift), 2.0 - 1e-3) << i;
    EXPECT_LE(std::abs(shift), 20.0 + 1e-3) << i;
    // Along the ray: the two points are collinear with the sensor origin.
    EXPECT_LT(p.cast<double>().normalized().cross(q.cast<double>().normalized()).norm(), 1e-6);
  }
  EXPECT_EQ(pulses, b->pulses);
  const double fraction = double(pulses) / a->hits;
  EXPECT_NEAR(fraction, 0.01, 0.001);
}

TEST(ScanSimulator, DentDeviationMatchesItsFormula) {
  ScanOptions opt;
  SurfaceDefect dent;
  dent.center_in_part = {5, 3, 0};
  dent.radius_mm = 6;
  dent.depth_mm = 0.3;
  opt.defects = {dent};
  const auto ws = SensorAbove();
  auto scan = SimulateScan(Plate(80), kWorldFromPart, ws, {}, opt);
  ASSERT_TRUE(scan.ok());
  const Eigen::Isometry3d part_from_sensor = kWorldFromPart.inverse() * ws;
  double deepest = 0;
  std::size_t defect_pixels = 0;
  for (std::size_t i = 0; i < scan->labels.size(); ++i) {
    if (!PointCloud::IsValid(scan->cloud_in_sensor.points[i])) continue;
    const Eigen::Vector3d p = part_from_sensor * scan->cloud_in_sensor.points[i].cast<double>();
    const double r2 = (Eigen::Vector3d(p.x(), p.y(), 0) - dent.center_in_part).squaredNorm();
    const double expected = -0.3 * std::exp(-r2 / (2 * 3.0 * 3.0));
    ASSERT_NEAR(p.z(), expected, 2e-5) << i;  // float32 storage of ~400 mm coordinates
    ASSERT_NEAR(scan->true_deviation_mm[i], expected, 1e-6) << i;
    EXPECT_EQ(scan->labels[i] == PixelLabel::kDefect, std::abs(expected) >= 1e-3 - 1e-9) << i;
    defect_pixels += scan->labels[i] == PixelLabel::kDefect;
    deepest = std::min(deepest, p.z());
  }
  EXPECT_NEAR(deepest, -0.3, 0.005);
  EXPECT_EQ(defect_pixels, scan->defect_pixels);
  EXPECT_GT(defect_pixels, 500u);
}

TEST(ScanSimulator, StripesSitBetweenTheTwoSurfacesOfAStep) {
  ScanOptions opt;
  opt.stripes = true;
  opt.seed = 3;
  const Eigen::Isometry3d world_from_part = Eigen::Isometry3d::Identity();
  const Eigen::Isometry3d ws = LookAt({-40, 0, 400}, {0, 0, 0});
  auto scan = SimulateScan(Step(), world_from_part, ws, {}, opt);
  ASSERT_TRUE(scan.ok());
  ASSERT_GT(scan->stripe_pixels, 20u);
  std::size_t checked = 0;
  for (std::size_t i = 0; i < scan->labels.size(); ++i) {
    if (scan->labels[i] != PixelLabel::kStripe) continue;
    const Eigen::Vector3d p = ws * scan->cloud_in_sensor.points[i].cast<double>();
    // A mixed pixel lies behind the near edge and on neither plate: between
    // the plates at the step, or trailing into the void at the outer edges.
    EXPECT_LT(p.z(), -0.5) << i;
    EXPECT_GT(std::min(std::abs(p.z()), std::abs(p.z() + 20.0)), 0.5) << i;
    ++checked;
  }
  EXPECT_EQ(checked, scan->stripe_pixels);
}

TEST(ScanSimulator, SameSeedSameBytes) {
  ScanOptions opt;
  opt.noise_sigma_mm = 0.02;
  opt.pulse_fraction = 0.005;
  opt.stripes = true;
  opt.defects = {SurfaceDefect{{0, 0, 0}, 5, 0.2}};
  opt.seed = 77;
  const auto ws = LookAt({-40, 10, 400}, {0, 0, 0});
  auto a = SimulateScan(Step(), Eigen::Isometry3d::Identity(), ws, {}, opt);
  auto b = SimulateScan(Step(), Eigen::Isometry3d::Identity(), ws, {}, opt);
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(0, std::memcmp(a->cloud_in_sensor.points.data(), b->cloud_in_sensor.points.data(),
                           a->cloud_in_sensor.size() * 12));
  ASSERT_EQ(a->labels, b->labels);
  opt.seed = 78;
  auto c = SimulateScan(Step(), Eigen::Isometry3d::Identity(), ws, {}, opt);
  EXPECT_NE(0, std::memcmp(a->cloud_in_sensor.points.data(), c->cloud_in_sensor.points.data(),
                           a->cloud_in_sensor.size() * 12));
}

TEST(ScanSimulator, OutOfRangeIsNoData) {
  SensorIntrinsics in;
  in.max_range_mm = 300;  // the plate is ~400 mm away
  auto scan = SimulateScan(Plate(60), kWorldFromPart, SensorAbove(), in, {});
  ASSERT_TRUE(scan.ok());
  EXPECT_EQ(scan->hits, 0u);
  EXPECT_EQ(scan->cloud_in_sensor.CountValid(), 0u);
}

TEST(ScanSimulator, RejectsBadParameters) {
  const auto ws = SensorAbove();
  SensorIntrinsics zero;
  zero.width = 0;
  EXPECT_FALSE(SimulateScan(Plate(60), kWorldFromPart, ws, zero, {}).ok());
  SensorIntrinsics fov;
  fov.horizontal_fov_deg = std::nan("");
  EXPECT_FALSE(SimulateScan(Plate(60), kWorldFromPart, ws, fov, {}).ok());
  ScanOptions neg;
  neg.noise_sigma_mm = -1;
  EXPECT_FALSE(SimulateScan(Plate(60), kWorldFromPart, ws, {}, neg).ok());
  ScanOptions bad_dent;
  bad_dent.defects = {SurfaceDefect{{0, 0, 0}, 0, 0.1}};
  EXPECT_FALSE(SimulateScan(Plate(60), kWorldFromPart, ws, {}, bad_dent).ok());
  EXPECT_FALSE(SimulateScan(TriangleMesh{}, kWorldFromPart, ws, {}, {}).ok());
}

}  // namespace
}  // namespace surfinspect
