#include "core/plan/pinhole_rays.h"

#include <tbb/parallel_for.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"

namespace surfinspect {
namespace {

constexpr std::size_t kMinPoints = 100;
constexpr std::size_t kTargetSamples = 20000;  // a stride over the grid; plenty for 6 unknowns
constexpr double kMaxRmsPx = 0.5;
constexpr std::size_t kBlock = std::size_t{1} << 16;  // pixels per parallel block

// Every stride-th valid pixel in storage order (stride: the valid count /
// kTargetSamples, at least 1), found in two parallel passes over blocks of
// the grid: the valid count of each block, then each block's picks from
// where its valid pixels start in the count.
std::vector<std::size_t> StrideSample(const PointCloud& grid) {
  const std::size_t n = grid.points.size(), blocks = (n + kBlock - 1) / kBlock;
  std::vector<std::size_t> before(blocks + 1, 0);
  tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
    for (std::size_t i = b * kBlock; i < std::min(n, (b + 1) * kBlock); ++i)
      before[b + 1] += PointCloud::IsValid(grid.points[i]);
  });
  for (std::size_t b = 0; b < blocks; ++b) before[b + 1] += before[b];
  const std::size_t stride = std::max<std::size_t>(1, before[blocks] / kTargetSamples);
  std::vector<std::vector<std::size_t>> picks(blocks);
  tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
    std::size_t seen = before[b];
    for (std::size_t i = b * kBlock; i < std::min(n, (b + 1) * kBlock); ++i)
      if (PointCloud::IsValid(grid.points[i]) && seen++ % stride == 0) picks[b].push_back(i);
  });
  std::vector<std::size_t> out;
  for (const auto& p : picks) out.insert(out.end(), p.begin(), p.end());
  return out;
}

}  // namespace

absl::StatusOr<PinholeRays> FitPinholeRays(const PointCloud& grid) {
  if (!grid.organized())
    return absl::InvalidArgumentError("pixel rays: the cloud is not organized");
  const std::vector<std::size_t> sample = StrideSample(grid);
  if (sample.size() < kMinPoints)
    return absl::InvalidArgumentError(absl::StrCat(
        "pixel rays: ", sample.size(), " valid points; at least ", kMinPoints, " needed"));
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Matrix<double, 3, 2> atb = Eigen::Matrix<double, 3, 2>::Zero();
  double zsum = 0;
  std::size_t used = 0;
  for (std::size_t i : sample) {
    const Eigen::Vector3f& p = grid.points[i];
    if (p.z() == 0) continue;
    const Eigen::Vector3d px(double(i % grid.width), double(i / grid.width), 1);
    ata += px * px.transpose();
    atb += px * Eigen::RowVector2d(p.x() / p.z(), p.y() / p.z());
    zsum += p.z();
    ++used;
  }
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(ata);
  if (used < kMinPoints || !lu.isInvertible())
    return absl::InvalidArgumentError("pixel rays: the valid pixels do not span the grid");
  PinholeRays rays;
  rays.affine = lu.solve(atb).transpose();
  rays.sign = zsum < 0 ? -1 : 1;
  // The residual in pixels: (a, b) errors mapped back through the affine.
  const Eigen::Matrix2d to_px = rays.affine.leftCols<2>().inverse();
  double ss = 0;
  for (std::size_t i : sample) {
    const Eigen::Vector3f& p = grid.points[i];
    if (p.z() == 0) continue;
    const Eigen::Vector2d ab(p.x() / p.z(), p.y() / p.z());
    const Eigen::Vector2d fit =
        rays.affine * Eigen::Vector3d(double(i % grid.width), double(i / grid.width), 1);
    ss += (to_px * (ab - fit)).squaredNorm();
  }
  rays.rms_px = std::sqrt(ss / double(used));
  if (!(rays.rms_px <= kMaxRmsPx))
    return absl::InvalidArgumentError(absl::StrCat(
        "pixel rays: the grid is not a pinhole camera's (residual ", rays.rms_px, " px)"));
  return rays;
}

bool ProjectToPixel(const PinholeRays& rays, const Eigen::Vector3d& p, Eigen::Vector2d* pixel) {
  if (!(p.z() * rays.sign > 0)) return false;
  const Eigen::Vector2d ab(p.x() / p.z(), p.y() / p.z());
  *pixel = rays.affine.leftCols<2>().inverse() * (ab - rays.affine.col(2));
  return pixel->allFinite();
}

}  // namespace surfinspect
