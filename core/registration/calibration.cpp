#include "core/registration/calibration.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/types/percentile.h"
#include "core/types/status_macros.h"
#include "core/types/transform.h"

namespace surfinspect {
namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return s;
}

// λmin/λmax of the normal matrix re-expressed about the inliers' centroid c
// with rotation scaled by their radius L. With J = B J' for
// J' = [(p-c)×n, n] and B = [[I, [c]×], [0, I]], H' = B⁻¹ H B⁻ᵀ.
double DegeneracyRatio(const IcpResult& icp) {
  Eigen::Matrix<double, 6, 6> b_inv = Eigen::Matrix<double, 6, 6>::Identity();
  b_inv.topRightCorner<3, 3>() = -Skew(icp.inlier_centroid);
  Eigen::Matrix<double, 6, 6> h = b_inv * icp.normal_matrix * b_inv.transpose();
  const double l = std::max(icp.inlier_radius_mm, 1e-9);
  Eigen::Matrix<double, 6, 6> scale = Eigen::Matrix<double, 6, 6>::Identity();
  scale.topLeftCorner<3, 3>() *= 1.0 / l;
  h = scale * h * scale;
  const Eigen::Matrix<double, 6, 1> ev =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>>(h).eigenvalues();
  return ev(5) > 0 ? std::max(0.0, ev(0)) / ev(5) : 0.0;
}

// Truncated cost of a pose: mean of min(d, cap)^2 over the sample.
absl::StatusOr<double> TruncatedCost(const MeshIndex& gauge, const PointCloud& sample,
                                     const Eigen::Isometry3d& gauge_from_sensor, double cap,
                                     int threads, const std::atomic<bool>* cancel) {
  BatchQuerySettings q;
  q.max_distance_mm = cap;
  q.threads = threads;
  ASSIGN_OR_RETURN(auto closest, QueryClosest(gauge, sample, gauge_from_sensor, q, cancel));
  double sum = 0;
  for (const auto& c : closest) sum += c.matched() ? c.distance_mm * c.distance_mm : cap * cap;
  return sum / double(closest.size());
}

// The coarse search of CalibrationSettings: rotations about the sensor
// origin (right-multiplied), the dominant part of a robot pose error, scored
// by truncated cost; the best few are refined by a short point-to-plane ICP
// on the same sample, and the lowest refined cost wins.
absl::StatusOr<Eigen::Isometry3d> CoarseSearch(const MeshIndex& gauge, const PointCloud& scan,
                                               const Eigen::Isometry3d& initial,
                                               const CalibrationSettings& s,
                                               const std::atomic<bool>* cancel) {
  std::vector<Eigen::Vector3f> pts;
  scan.ForEachValid([&](std::size_t, const Eigen::Vector3f& p) { pts.push_back(p); });
  if (pts.size() > s.coarse_points) {
    std::vector<Eigen::Vector3f> sub;
    const double stride = double(pts.size()) / s.coarse_points;
    for (std::size_t k = 0; k < s.coarse_points; ++k) sub.push_back(pts[std::size_t(k * stride)]);
    pts.swap(sub);
  }
  const PointCloud sample = PointCloud::Unorganized(std::move(pts));
  const int steps = static_cast<int>(std::floor(s.coarse_search_deg / s.coarse_step_deg + 1e-9));
  const double cap = 10.0, d = s.coarse_step_deg * M_PI / 180;
  std::vector<std::pair<double, Eigen::Isometry3d>> scored;
  for (int i = -steps; i <= steps; ++i)
    for (int j = -steps; j <= steps; ++j)
      for (int k = -steps; k <= steps; ++k) {
        Eigen::Isometry3d r = Eigen::Isometry3d::Identity();
        r.linear() = (Eigen::AngleAxisd(i * d, Eigen::Vector3d::UnitX()) *
                      Eigen::AngleAxisd(j * d, Eigen::Vector3d::UnitY()) *
                      Eigen::AngleAxisd(k * d, Eigen::Vector3d::UnitZ()))
                         .toRotationMatrix();
        ASSIGN_OR_RETURN(auto cost,
                         TruncatedCost(gauge, sample, initial * r, cap, s.icp.threads, cancel));
        scored.emplace_back(cost, initial * r);
      }
  const std::size_t keep = std::min<std::size_t>(6, scored.size());
  std::partial_sort(scored.begin(), scored.begin() + keep, scored.end(),
                    [](const auto& a, const auto& b) { return a.first < b.first; });
  IcpSettings refine;
  refine.step = IcpStep::kPointToPlane;
  refine.max_iterations = 15;
  refine.max_correspondence_mm = 2 * cap;
  refine.max_points = 0;
  refine.threads = s.icp.threads;
  double best_value = INFINITY;
  Eigen::Isometry3d best = initial;
  for (std::size_t c = 0; c < keep; ++c) {
    auto icp = RunIcp(gauge, sample, scored[c].second, refine, cancel);
    if (icp.status().code() == absl::StatusCode::kCancelled) return icp.status();
    if (!icp.ok()) continue;  // a hopeless candidate: too few pairs
    ASSIGN_OR_RETURN(
        auto cost, TruncatedCost(gauge, sample, icp->mesh_from_points, cap, s.icp.threads, cancel));
    if (cost < best_value) {
      best_value = cost;
      best = icp->mesh_from_points;
    }
  }
  return best;
}

absl::Status CheckCalibrationSettings(const CalibrationSettings& s) {
  if (!(s.degeneracy_threshold >= 0 && s.degeneracy_threshold < 1))
    return absl::InvalidArgumentError("calibration: degeneracy_threshold must be in [0, 1)");
  if (!(s.coarse_search_deg >= 0 && s.coarse_search_deg <= 30) ||
      (s.coarse_search_deg > 0 && !(s.coarse_step_deg >= 0.1)) || s.coarse_points < 10)
    return absl::InvalidArgumentError(
        "calibration: coarse_search_deg in [0, 30], coarse_step_deg >= 0.1, coarse_points >= 10");
  return absl::OkStatus();
}

// RMS, percentiles of |residual| and the inlier fraction of the final ICP.
void SummarizeResiduals(CalibrationResult& r) {
  const std::vector<double>& res = r.icp.residuals_mm;
  double sum2 = 0;
  std::vector<double> abs_res;
  abs_res.reserve(res.size());
  for (double e : res) {
    sum2 += e * e;
    abs_res.push_back(std::abs(e));
  }
  r.rms_mm = std::sqrt(sum2 / double(res.size()));
  if (!abs_res.empty()) {
    Percentiles<double> p(abs_res);  // increasing q, as it requires
    r.residual_p50_mm = p.At(0.50);
    r.residual_p95_mm = p.At(0.95);
    r.residual_p99_mm = p.At(0.99);
  }
  r.inlier_fraction = double(r.icp.inliers) / double(r.icp.points_used);
}

// Degeneracy flag and the warnings a user should read.
void Assess(const CalibrationSettings& s, CalibrationResult& r) {
  r.degeneracy_ratio = DegeneracyRatio(r.icp);
  r.degenerate = r.degeneracy_ratio < s.degeneracy_threshold;
  if (r.degenerate)
    r.warnings.push_back(
        absl::StrCat("degenerate: the gauge scan does not constrain all six degrees of freedom "
                     "(eigenvalue ratio ",
                     r.degeneracy_ratio, " < ", s.degeneracy_threshold,
                     "); rescan so that non-parallel surfaces are in view"));
  if (!r.icp.converged)
    r.warnings.push_back(absl::StrCat("ICP stopped at max_iterations (", r.icp.iterations, ")"));
}

// Covariance σ² (JᵀJ)⁻¹ with σ² from the residuals (n - 6 dof), and its 1-σ
// figures at the sensor origin. A singular normal matrix (degenerate scan)
// leaves the covariance unbounded.
void EstimateCovariance(CalibrationResult& r) {
  const std::vector<double>& res = r.icp.residuals_mm;
  double sum2 = 0;
  for (double e : res) sum2 += e * e;
  const double n = double(res.size());
  const Eigen::FullPivLU<Eigen::Matrix<double, 6, 6>> lu(r.icp.normal_matrix);
  if (n > 6 && lu.isInvertible()) {
    const double sigma2 = sum2 / (n - 6);
    r.covariance = sigma2 * lu.inverse();
    // The sensor origin o moves by ω×o + t = [-[o]×, I] x.
    Eigen::Matrix<double, 3, 6> a;
    a << -Skew(r.gauge_from_sensor.translation()), Eigen::Matrix3d::Identity();
    const Eigen::Matrix3d cov_origin = a * r.covariance * a.transpose();
    r.sigma_translation_um = 1000.0 * std::sqrt(std::max(0.0, cov_origin.trace()));
    r.sigma_rotation_deg =
        std::sqrt(std::max(0.0, r.covariance.topLeftCorner<3, 3>().trace())) * 180.0 / M_PI;
  } else {
    r.covariance.setConstant(INFINITY);
    r.sigma_translation_um = INFINITY;
    r.sigma_rotation_deg = INFINITY;
  }
}

}  // namespace

absl::StatusOr<CalibrationResult> CalibrateViewpoint(
    const MeshIndex& gauge_in_gauge, const Eigen::Isometry3d& world_from_gauge,
    const PointCloud& scan_in_sensor, const Eigen::Isometry3d& initial_world_from_sensor,
    const CalibrationSettings& s, const std::atomic<bool>* cancel) {
  RETURN_IF_ERROR(CheckCalibrationSettings(s));
  RETURN_IF_ERROR(scan_in_sensor.Validate());
  CalibrationResult r;
  r.scan_points = scan_in_sensor.CountValid();
  const PointCloud* scan = &scan_in_sensor;
  PointCloud filtered;
  if (s.filter_outliers) {
    filtered = scan_in_sensor;
    LinkClusteringResult clusters;
    RETURN_IF_ERROR(RemoveOutliers(filtered, s.filter, clusters, cancel));
    r.filtered_points = clusters.removed;
    scan = &filtered;
  }

  Eigen::Isometry3d initial_gauge_from_sensor =
      world_from_gauge.inverse() * initial_world_from_sensor;
  if (s.coarse_search_deg > 0) {
    ASSIGN_OR_RETURN(auto coarse,
                     CoarseSearch(gauge_in_gauge, *scan, initial_gauge_from_sensor, s, cancel));
    r.coarse_rotation_deg = ComparePoses(initial_gauge_from_sensor, coarse).rotation_deg;
    initial_gauge_from_sensor = coarse;
  }
  ASSIGN_OR_RETURN(auto icp,
                   RunIcp(gauge_in_gauge, *scan, initial_gauge_from_sensor, s.icp, cancel));
  r.icp = std::move(icp);
  r.gauge_from_sensor = r.icp.mesh_from_points;
  // The paper's eq. (1): world_from_sensor_i = world_from_gauge_i * gauge_from_sensor_i.
  r.world_from_sensor = world_from_gauge * r.gauge_from_sensor;
  SummarizeResiduals(r);
  Assess(s, r);
  EstimateCovariance(r);
  return r;
}

}  // namespace surfinspect
