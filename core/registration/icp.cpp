#include "core/registration/icp.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "absl/strings/str_cat.h"
#include "core/registration/absolute_orientation.h"
#include "core/types/cancel.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

double KernelWeight(const IcpSettings& s, double r) {
  const double a = std::abs(r);
  switch (s.kernel) {
    case RobustKernel::kNone:
      return 1.0;
    case RobustKernel::kHuber:
      return a <= s.kernel_scale_mm ? 1.0 : s.kernel_scale_mm / a;
    case RobustKernel::kTukey: {
      if (a >= s.kernel_scale_mm) return 0.0;
      const double u = 1.0 - (a / s.kernel_scale_mm) * (a / s.kernel_scale_mm);
      return u * u;
    }
  }
  return 1.0;
}

// The points ICP works on: the valid ones, subsampled with a fixed seed and
// kept in their original (scan) order so closest-point queries stay coherent.
PointCloud Subsample(const PointCloud& cloud, std::size_t max_points, uint64_t seed) {
  std::vector<uint32_t> valid;
  cloud.ForEachValid([&](std::size_t i, const Eigen::Vector3f&) { valid.push_back(uint32_t(i)); });
  if (max_points > 0 && valid.size() > max_points) {
    std::mt19937_64 rng(seed);
    for (std::size_t i = 0; i < max_points; ++i)
      std::swap(valid[i], valid[i + rng() % (valid.size() - i)]);
    valid.resize(max_points);
    std::sort(valid.begin(), valid.end());
  }
  std::vector<Eigen::Vector3f> pts;
  pts.reserve(valid.size());
  for (uint32_t i : valid) pts.push_back(cloud.points[i]);
  return PointCloud::Unorganized(std::move(pts));
}

struct Pairs {
  std::vector<Eigen::Vector3d> p;  // point, moved into the mesh frame
  std::vector<Eigen::Vector3d> q;  // closest point on the mesh
  std::vector<Eigen::Vector3d> n;  // unit normal of the closest feature
  std::vector<double> w;           // robust weight
  double cost = 0;                 // mean squared distance, mm^2
};

// Pairs within the gate (and the trim), with weights, at the given pose.
absl::StatusOr<Pairs> Correspond(const MeshIndex& mesh, const PointCloud& pts,
                                 const Eigen::Isometry3d& pose, double gate, const IcpSettings& s,
                                 const std::atomic<bool>* cancel) {
  BatchQuerySettings q;
  q.max_distance_mm = gate;
  q.threads = s.threads;
  ASSIGN_OR_RETURN(auto closest, QueryClosest(mesh, pts, pose, q, cancel));
  std::vector<double> dist;
  dist.reserve(closest.size());
  for (const auto& c : closest)
    if (c.matched()) dist.push_back(c.distance_mm);
  double trim_at = INFINITY;
  if (s.trim_fraction > 0 && !dist.empty()) {
    const std::size_t k =
        std::min(dist.size() - 1, std::size_t((1.0 - s.trim_fraction) * dist.size()));
    std::nth_element(dist.begin(), dist.begin() + k, dist.end());
    trim_at = dist[k];
  }
  Pairs out;
  double sum2 = 0;
  for (std::size_t i = 0; i < closest.size(); ++i) {
    const ClosestPoint& c = closest[i];
    if (!c.matched() || c.distance_mm > trim_at) continue;
    const Eigen::Vector3d p = pose * pts.points[i].cast<double>();
    // Inside a face the plane normal; at an edge or vertex the direction to
    // the point, which is the normal of the distance field there.
    Eigen::Vector3d n = c.normal;
    if (c.feature != ClosestFeature::kFace && c.distance_mm > 1e-9)
      n = (p - c.point) / c.distance_mm;
    if (n.squaredNorm() < 0.5) continue;  // degenerate triangle, no usable normal
    const double r = s.step == IcpStep::kPointToPlane ? (p - c.point).dot(n) : c.distance_mm;
    out.p.push_back(p);
    out.q.push_back(c.point);
    out.n.push_back(n);
    out.w.push_back(KernelWeight(s, r));
    sum2 += c.distance_mm * c.distance_mm;
  }
  // The paper's cost Δ_i of eq. (4), as a mean over the pairs (mm²).
  out.cost = out.p.empty() ? INFINITY : sum2 / out.p.size();
  return out;
}

Eigen::Matrix<double, 6, 6> NormalMatrix(const Pairs& pr, Eigen::Matrix<double, 6, 1>* rhs) {
  Eigen::Matrix<double, 6, 6> h = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
  for (std::size_t i = 0; i < pr.p.size(); ++i) {
    // r(x) ≈ (p - q)·n + ω·(p × n) + t·n for exp([ω, t]) applied on the left.
    Eigen::Matrix<double, 6, 1> j;
    j << pr.p[i].cross(pr.n[i]), pr.n[i];
    const double r = (pr.p[i] - pr.q[i]).dot(pr.n[i]);
    h += pr.w[i] * j * j.transpose();
    b += pr.w[i] * r * j;
  }
  if (rhs) *rhs = b;
  return h;
}

absl::StatusOr<Eigen::Isometry3d> Step(const Pairs& pr, const IcpSettings& s) {
  // Point-to-point: the T_i minimising eq. (4) in closed form (Horn's quaternion method).
  if (s.step == IcpStep::kPointToPoint) return HornAbsoluteOrientation(pr.p, pr.q, pr.w);
  Eigen::Matrix<double, 6, 1> b;
  const Eigen::Matrix<double, 6, 6> h = NormalMatrix(pr, &b);
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(h);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive())
    return absl::FailedPreconditionError("icp: point-to-plane system is singular");
  const Eigen::Matrix<double, 6, 1> x = ldlt.solve(-b);
  if (!x.allFinite())
    return absl::FailedPreconditionError("icp: point-to-plane step is not finite");
  Eigen::Isometry3d d = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d w = x.head<3>();
  if (w.norm() > 0) d.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
  d.translation() = x.tail<3>();
  return d;
}

}  // namespace

absl::Status ValidateIcpSettings(const IcpSettings& s) {
  auto bad = [](absl::string_view what, double v) {
    return absl::InvalidArgumentError(absl::StrCat("icp: ", what, ", got ", v));
  };
  if (s.max_iterations < 0 || s.max_iterations > kMaxIcpIterations)
    return bad(absl::StrCat("max_iterations must be in [0, ", kMaxIcpIterations, "]"),
               s.max_iterations);
  if (!(s.max_correspondence_mm > 0) || !std::isfinite(s.max_correspondence_mm))
    return bad("max_correspondence_mm must be finite and > 0", s.max_correspondence_mm);
  if (!(s.min_correspondence_mm > 0) || s.min_correspondence_mm > s.max_correspondence_mm)
    return bad("min_correspondence_mm must be > 0 and <= max_correspondence_mm",
               s.min_correspondence_mm);
  if (!(s.trim_fraction >= 0 && s.trim_fraction < 0.9))
    return bad("trim_fraction must be in [0, 0.9)", s.trim_fraction);
  if (!(s.kernel_scale_mm > 0)) return bad("kernel_scale_mm must be > 0", s.kernel_scale_mm);
  if (!(s.relative_cost_tolerance >= 0) || !std::isfinite(s.relative_cost_tolerance))
    return bad("relative_cost_tolerance must be finite and >= 0", s.relative_cost_tolerance);
  if (!(s.absolute_cost_mm2 >= 0))
    return bad("absolute_cost_mm2 must be >= 0", s.absolute_cost_mm2);
  return absl::OkStatus();
}

const char* ToString(IcpStopReason reason) {
  switch (reason) {
    case IcpStopReason::kRelativeChange:
      return "relative_change";
    case IcpStopReason::kAbsoluteCost:
      return "absolute_cost";
    case IcpStopReason::kMaxIterations:
      return "max_iterations";
  }
  return "unknown";
}

absl::StatusOr<IcpResult> RunIcp(const MeshIndex& mesh, const PointCloud& points,
                                 const Eigen::Isometry3d& initial_mesh_from_points,
                                 const IcpSettings& s, const std::atomic<bool>* cancel) {
  RETURN_IF_ERROR(ValidateIcpSettings(s));
  RETURN_IF_ERROR(points.Validate());
  if (!initial_mesh_from_points.matrix().allFinite())
    return absl::InvalidArgumentError("icp: initial pose is not finite");
  const PointCloud pts = Subsample(points, s.max_points, s.seed);
  if (pts.size() < 6) return absl::InvalidArgumentError("icp: fewer than 6 valid points");

  IcpResult result;
  result.points_used = pts.size();
  Eigen::Isometry3d pose = initial_mesh_from_points;
  double gate = s.max_correspondence_mm, previous_gate = gate;
  for (int it = 0;; ++it) {
    if (IsCancelled(cancel)) return absl::CancelledError("icp cancelled");
    ASSIGN_OR_RETURN(auto pairs, Correspond(mesh, pts, pose, gate, s, cancel));
    if (pairs.p.size() < 6)
      return absl::FailedPreconditionError(
          absl::StrCat("icp: only ", pairs.p.size(), " of ", pts.size(), " points within ", gate,
                       " mm of the mesh at iteration ", it, "; is the initial pose too far off?"));
    const std::vector<double>& h = result.cost_history;
    result.cost_history.push_back(pairs.cost);
    result.mesh_from_points = pose;
    result.iterations = it;
    result.inliers = pairs.p.size();
    result.rms_mm = std::sqrt(pairs.cost);
    bool stop = false;
    if (pairs.cost <= s.absolute_cost_mm2) {
      result.stop_reason = IcpStopReason::kAbsoluteCost;
      stop = true;
    } else if (it >= 1) {
      // The paper's eq. (5): δ = (Δ_i − Δ_{i−1}) / (Δ_{i−1} − Δ_{i−2}), here
      // as the ratio of successive decreases; the gain still to come is the
      // geometric tail (Δ_{i−1} − Δ_i)·δ/(1 − δ).
      const double dec1 = h[it - 1] - h[it];
      const double delta =
          it >= 2 && h[it - 2] - h[it - 1] > 0 ? dec1 / (h[it - 2] - h[it - 1]) : -1;
      const bool rate_usable = delta >= 0 && delta < 1;
      const double remaining = rate_usable ? dec1 * delta / (1 - delta) : std::abs(dec1);
      // A step that no longer lowers the cost (with the gate unchanged, so
      // the costs compare like with like) has reached the noise floor.
      const bool stalled = dec1 <= 0 && gate == previous_gate;
      if (stalled || (dec1 >= 0 && remaining <= s.relative_cost_tolerance * h[it])) {
        result.stop_reason = IcpStopReason::kRelativeChange;
        stop = true;
      }
    }
    if (stop || it >= s.max_iterations) {
      result.converged = stop;
      if (!stop) result.stop_reason = IcpStopReason::kMaxIterations;
      result.normal_matrix = NormalMatrix(pairs, nullptr);
      result.residuals_mm.reserve(pairs.p.size());
      for (std::size_t i = 0; i < pairs.p.size(); ++i) {
        result.residuals_mm.push_back((pairs.p[i] - pairs.q[i]).dot(pairs.n[i]));
        result.inlier_centroid += pairs.p[i];
      }
      result.inlier_centroid /= double(pairs.p.size());
      double r2 = 0;
      for (const auto& p : pairs.p) r2 += (p - result.inlier_centroid).squaredNorm();
      result.inlier_radius_mm = std::sqrt(r2 / pairs.p.size());
      return result;
    }
    ASSIGN_OR_RETURN(auto delta, Step(pairs, s));
    pose = delta * pose;
    previous_gate = gate;
    gate = std::clamp(4.0 * result.rms_mm, s.min_correspondence_mm, s.max_correspondence_mm);
  }
}

}  // namespace surfinspect
