#include "core/registration/locked_best_fit.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/types/cancel.h"
#include "core/types/percentile.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

// Points per chunk of the normal equations: the chunks, and so the order of
// the floating-point sums, are the same with any number of threads.
constexpr std::size_t kChunk = 8192;

// A point's pair at the current pose: the unit normal of the distance field
// at its closest point and the signed residual along it; r is NaN when the
// point has no pair (no data, beyond the gate, outside the region).
struct Pair {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  double r = NAN;
};

absl::Status Correspond(const MeshIndex& mesh, const PointCloud& points, const RigidMotion& motion,
                        const std::vector<uint8_t>& mask, const LockedBestFitSettings& s,
                        const std::atomic<bool>* cancel, std::vector<Pair>& pairs) {
  BatchQuerySettings q;
  q.max_distance_mm = s.max_correspondence_mm;
  q.threads = s.threads;
  return QueryClosestEach(
      mesh, points, motion.transform(), q, cancel, [&](std::size_t i, const ClosestPoint& c) {
        Pair& pair = pairs[i];
        pair.r = NAN;
        if (!c.matched() || (!mask.empty() && !mask[c.triangle_id])) return;
        const Eigen::Vector3d p = motion.transform() * points.points[i].cast<double>();
        // Inside a face its plane's normal; at an edge or a vertex the
        // direction to the point, the distance field's gradient there (as
        // in icp.cpp's pairs).
        Eigen::Vector3d n = c.normal;
        if (c.feature != ClosestFeature::kFace && c.distance_mm > 1e-9)
          n = (p - c.point) / c.distance_mm;
        if (n.squaredNorm() < 0.5) return;  // degenerate triangle, no usable normal
        pair.n = n;
        pair.r = (p - c.point).dot(n);
      });
}

// σ = MadSigma of the residuals (core/types/percentile.h), at least
// `floor_mm`.
double RobustScale(const std::vector<Pair>& pairs, double floor_mm) {
  std::vector<double> a;
  for (const Pair& p : pairs)
    if (!std::isnan(p.r)) a.push_back(std::abs(p.r));
  if (a.empty()) return floor_mm;
  return std::max(MadSigma(a), floor_mm);
}

// IRLS weight of a residual with cut-off c: Huber min(1, c/|r|), Tukey's
// biweight (1 − (r/c)²)² inside c and 0 beyond.
double RobustWeight(RobustKernel kernel, double r, double c) {
  const double a = std::abs(r);
  switch (kernel) {
    case RobustKernel::kNone:
      return 1.0;
    case RobustKernel::kHuber:
      return a <= c ? 1.0 : c / a;
    case RobustKernel::kTukey: {
      if (a >= c) return 0.0;
      const double u = 1.0 - (a / c) * (a / c);
      return u * u;
    }
  }
  return 1.0;
}

// Σ w·rowᵀ·row and Σ w·r·rowᵀ with row = n·∂(T·p)/∂x, over all six DOFs.
struct NormalSums {
  DofMatrix h = DofMatrix::Zero();
  RigidParams g = RigidParams::Zero();
  double sum_r2 = 0;  // unweighted, mm²
  std::size_t pairs = 0, inliers = 0;
};

NormalSums Accumulate(const PointCloud& points, const std::vector<Pair>& pairs,
                      const RigidMotion& motion, RobustKernel kernel, double cut_mm, int threads) {
  const std::size_t chunks = (pairs.size() + kChunk - 1) / kChunk;
  std::vector<NormalSums> part(chunks);
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks, 1), [&](const auto& range) {
      for (std::size_t c = range.begin(); c != range.end(); ++c) {
        NormalSums& sums = part[c];
        for (std::size_t i = c * kChunk; i < std::min(pairs.size(), (c + 1) * kChunk); ++i) {
          const Pair& pair = pairs[i];
          if (std::isnan(pair.r)) continue;
          ++sums.pairs;
          sums.sum_r2 += pair.r * pair.r;
          const double w = RobustWeight(kernel, pair.r, cut_mm);
          if (!(w > 0)) continue;
          ++sums.inliers;
          const RigidParams row =
              (pair.n.transpose() * motion.Jacobian(points.points[i].cast<double>())).transpose();
          sums.h.noalias() += w * row * row.transpose();
          sums.g.noalias() += (w * pair.r) * row;
        }
      }
    });
  });
  NormalSums total;
  for (const NormalSums& p : part) {  // in chunk order, whatever the threads
    total.h += p.h;
    total.g += p.g;
    total.sum_r2 += p.sum_r2;
    total.pairs += p.pairs;
    total.inliers += p.inliers;
  }
  return total;
}

// The analysis of rigid_dofs.h on the x = 0 normal matrix, whose rows are
// [n, p × n]: about the box's centre c, rotations over its half diagonal L,
// the rows become M·row with M = [[I, 0], [−[c]×/L, I/L]].
DofAnalysis AnalyseAtZero(const DofMatrix& h, const Bounds3& box, const LockedDofs& locked) {
  const Eigen::Vector3d c = 0.5 * (box.min + box.max);
  const double length = std::max(0.5 * (box.max - box.min).norm(), 1.0);
  DofMatrix m = DofMatrix::Zero();
  m.topLeftCorner<3, 3>().setIdentity();
  Eigen::Matrix3d cross;
  cross << 0, -c.z(), c.y(), c.z(), 0, -c.x(), -c.y(), c.x(), 0;
  m.bottomLeftCorner<3, 3>() = -cross / length;
  m.bottomRightCorner<3, 3>() = Eigen::Matrix3d::Identity() / length;
  return AnalyseDofs(m * h * m.transpose(), locked);
}

// The largest displacement of a box corner by `b` relative to `a`: the
// displacement of a rigid motion is affine in the point, so its length is
// largest at a corner of any box that holds the points.
double LargestCornerMotion(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                           const Bounds3& box) {
  double largest = 0;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d corner((k & 1 ? box.max : box.min).x(), (k & 2 ? box.max : box.min).y(),
                                 (k & 4 ? box.max : box.min).z());
    largest = std::max(largest, (b * corner - a * corner).norm());
  }
  return largest;
}

// The Gauss-Newton step on the free components: −H_ff⁻¹·g_f.
absl::StatusOr<RigidParams> FreeStep(const NormalSums& sums, const LockedDofs& locked, int it) {
  std::vector<int> free;
  for (int d = 0; d < kRigidDofs; ++d)
    if (!locked.IsLocked(d)) free.push_back(d);
  const int m = static_cast<int>(free.size());
  Eigen::MatrixXd h(m, m);
  Eigen::VectorXd g(m);
  for (int a = 0; a < m; ++a) {
    g[a] = sums.g[free[a]];
    for (int b = 0; b < m; ++b) h(a, b) = sums.h(free[a], free[b]);
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(h);
  const Eigen::VectorXd y = ldlt.solve(-g);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive() || !y.allFinite())
    return absl::FailedPreconditionError(
        absl::StrCat("best-fit: the normal matrix is singular at iteration ", it));
  RigidParams dx = RigidParams::Zero();
  for (int a = 0; a < m; ++a) dx[free[a]] = y[a];
  return dx;
}

}  // namespace

absl::Status ValidateLockedBestFitSettings(const LockedBestFitSettings& s) {
  auto bad = [](absl::string_view what, double v) {
    return absl::InvalidArgumentError(absl::StrCat("best-fit: ", what, ", got ", v));
  };
  auto positive = [](double v) { return v > 0 && std::isfinite(v); };
  if (s.max_iterations < 1 || s.max_iterations > 1000)
    return bad("max_iterations must be in [1, 1000]", s.max_iterations);
  if (!positive(s.max_correspondence_mm))
    return bad("max_correspondence_mm must be finite and > 0", s.max_correspondence_mm);
  if (!positive(s.kernel_sigmas))
    return bad("kernel_sigmas must be finite and > 0", s.kernel_sigmas);
  if (!positive(s.min_scale_mm)) return bad("min_scale_mm must be finite and > 0", s.min_scale_mm);
  if (!positive(s.convergence_mm))
    return bad("convergence_mm must be finite and > 0", s.convergence_mm);
  if (!(s.max_correction_mm > 0)) return bad("max_correction_mm must be > 0", s.max_correction_mm);
  if (!(s.max_correction_deg > 0))
    return bad("max_correction_deg must be > 0", s.max_correction_deg);
  if (s.threads < 0 || s.threads > kMaxQueryThreads)
    return bad(absl::StrCat("threads must be in [0, ", kMaxQueryThreads, "]"), s.threads);
  return absl::OkStatus();
}

namespace {

absl::Status ValidateInputs(const MeshIndex& mesh, const PointCloud& points,
                            const std::vector<uint8_t>& mask, const LockedBestFitSettings& s) {
  RETURN_IF_ERROR(ValidateLockedBestFitSettings(s));
  if (absl::Status st = points.Validate(); !st.ok())
    return absl::InvalidArgumentError(absl::StrCat("best-fit: points_in_part: ", st.message()));
  const std::size_t valid = points.CountValid();
  if (valid < 6)
    return absl::InvalidArgumentError(
        absl::StrCat("best-fit: points_in_part has ", valid, " valid points, need at least 6"));
  const std::size_t triangles = mesh.mesh().triangles.size();
  if (!mask.empty() && mask.size() != triangles)
    return absl::InvalidArgumentError(absl::StrCat("best-fit: triangle_mask has ", mask.size(),
                                                   " entries for ", triangles, " triangles"));
  return absl::OkStatus();
}

// Fills the result's figures of the pairs at the pose they were made at.
void Record(const NormalSums& sums, double scale_mm, LockedBestFitResult& out) {
  out.rms_after_mm = std::sqrt(sums.sum_r2 / static_cast<double>(sums.pairs));
  out.rms_history_mm.push_back(out.rms_after_mm);
  out.points_used = sums.pairs;
  out.inliers = sums.inliers;
  out.scale_mm = scale_mm;
}

// The correction's size against the allowed maximum.
void MeasureCorrection(const PointCloud& points, const std::vector<Pair>& pairs,
                       const LockedBestFitSettings& s, LockedBestFitResult& out) {
  const Eigen::Isometry3d& t = out.nominal_from_measured;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    if (std::isnan(pairs[i].r)) continue;
    const Eigen::Vector3d p = points.points[i].cast<double>();
    out.correction_mm = std::max(out.correction_mm, (t * p - p).norm());
  }
  out.correction_deg = Eigen::AngleAxisd(t.linear()).angle() * 180.0 / M_PI;
  out.exceeds_max_correction =
      out.correction_mm > s.max_correction_mm || out.correction_deg > s.max_correction_deg;
}

}  // namespace

absl::StatusOr<LockedBestFitResult> RunLockedBestFit(
    const MeshIndex& mesh, const PointCloud& points, const std::vector<uint8_t>& mask,
    const LockedDofs& locked, const LockedBestFitSettings& s, const std::atomic<bool>* cancel) {
  RETURN_IF_ERROR(ValidateInputs(mesh, points, mask, s));
  const Bounds3 box = ComputeBounds(points);
  std::vector<Pair> pairs(points.size());
  LockedBestFitResult out;
  out.converged = locked.FreeCount() == 0;  // nothing to fit
  for (int it = 0;; ++it) {
    if (IsCancelled(cancel)) return absl::CancelledError("best-fit cancelled");
    const RigidMotion motion(out.x);
    RETURN_IF_ERROR(Correspond(mesh, points, motion, mask, s, cancel, pairs));
    const double scale_mm = RobustScale(pairs, s.min_scale_mm);
    const NormalSums sums =
        Accumulate(points, pairs, motion, s.kernel, s.kernel_sigmas * scale_mm, s.threads);
    if (sums.pairs < 6)
      return absl::InvalidArgumentError(
          absl::StrCat("best-fit: only ", sums.pairs,
                       " points lie within max_correspondence_mm = ", s.max_correspondence_mm,
                       " of the mesh", mask.empty() ? "" : " in the region", " at iteration ", it));
    Record(sums, scale_mm, out);
    if (it == 0) {
      out.rms_before_mm = out.rms_after_mm;
      const DofAnalysis analysis = AnalyseAtZero(sums.h, box, locked);
      if (!analysis.free.empty())
        return absl::InvalidArgumentError(
            absl::StrCat("best-fit: the points leave free: ", JoinFree(analysis.free),
                         " (lock these degrees of freedom or fit a region that holds them)"));
      out.condition = analysis.condition;
    }
    if (out.converged || it >= s.max_iterations) break;
    ASSIGN_OR_RETURN(const RigidParams dx, FreeStep(sums, locked, it));
    const RigidParams next = out.x + dx;
    const double moved_mm =
        LargestCornerMotion(motion.transform(), RigidMotion(next).transform(), box);
    out.x = next;
    ++out.iterations;
    out.converged = moved_mm <= s.convergence_mm;
  }
  out.nominal_from_measured = RigidMotion(out.x).transform();
  MeasureCorrection(points, pairs, s, out);
  return out;
}

}  // namespace surfinspect
