#include "core/plan/pinhole_rays.h"

#include <Eigen/LU>
#include <cmath>

#include "absl/strings/str_cat.h"

namespace surfinspect {
namespace {

constexpr std::size_t kMinPoints = 100;
constexpr std::size_t kTargetSamples = 20000;  // a stride over the grid; plenty for 6 unknowns
constexpr double kMaxRmsPx = 0.5;

}  // namespace

absl::StatusOr<PinholeRays> FitPinholeRays(const PointCloud& grid) {
  if (!grid.organized())
    return absl::InvalidArgumentError("pixel rays: the cloud is not organized");
  const std::size_t valid = grid.CountValid();
  if (valid < kMinPoints)
    return absl::InvalidArgumentError(
        absl::StrCat("pixel rays: ", valid, " valid points; at least ", kMinPoints, " needed"));
  const std::size_t stride = std::max<std::size_t>(1, valid / kTargetSamples);
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Matrix<double, 3, 2> atb = Eigen::Matrix<double, 3, 2>::Zero();
  double zsum = 0;
  std::size_t seen = 0, used = 0;
  grid.ForEachValid([&](std::size_t i, const Eigen::Vector3f& p) {
    if (seen++ % stride != 0 || p.z() == 0) return;
    const Eigen::Vector3d px(double(i % grid.width), double(i / grid.width), 1);
    ata += px * px.transpose();
    atb += px * Eigen::RowVector2d(p.x() / p.z(), p.y() / p.z());
    zsum += p.z();
    ++used;
  });
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(ata);
  if (used < kMinPoints || !lu.isInvertible())
    return absl::InvalidArgumentError("pixel rays: the valid pixels do not span the grid");
  PinholeRays rays;
  rays.affine = lu.solve(atb).transpose();
  rays.sign = zsum < 0 ? -1 : 1;
  // The residual in pixels: (a, b) errors mapped back through the affine.
  const Eigen::Matrix2d to_px = rays.affine.leftCols<2>().inverse();
  double ss = 0;
  seen = 0;
  grid.ForEachValid([&](std::size_t i, const Eigen::Vector3f& p) {
    if (seen++ % stride != 0 || p.z() == 0) return;
    const Eigen::Vector2d ab(p.x() / p.z(), p.y() / p.z());
    const Eigen::Vector2d fit =
        rays.affine * Eigen::Vector3d(double(i % grid.width), double(i / grid.width), 1);
    ss += (to_px * (ab - fit)).squaredNorm();
  });
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
