#include "core/acceptance/flatness.h"

#include <cmath>

#include "absl/strings/str_format.h"
#include "core/acceptance/probing_error.h"

namespace surfinspect {

absl::StatusOr<Flatness> MeasureFlatness(const PointCloud& cloud, const PlaneSearch& s,
                                         double outlier_share, const std::string& what) {
  if (!(std::abs(s.normal_hint.norm() - 1) < 1e-6) || !(s.radius_mm > 0) || !(s.search_mm > 0) ||
      !(s.band_mm > 0))
    return absl::InvalidArgumentError(what + ": unit normal, radius, search and band > 0 needed");
  std::vector<Eigen::Vector3d> pts;
  cloud.ForEachValid([&](std::size_t, const Eigen::Vector3f& p) {
    const Eigen::Vector3d d = p.cast<double>() - s.centre_hint_mm;
    const double h = d.dot(s.normal_hint);
    if (std::abs(h) <= s.search_mm && (d - h * s.normal_hint).norm() <= s.radius_mm)
      pts.push_back(p.cast<double>());
  });
  Flatness f;
  f.candidates = pts.size();
  const auto too_few = [&](std::size_t n, const char* where) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "%s: %d points on the plate %s within %.1f mm of (%.2f, %.2f, %.2f) (at least %d needed)",
        what, n, where, s.radius_mm, s.centre_hint_mm.x(), s.centre_hint_mm.y(),
        s.centre_hint_mm.z(), s.min_points));
  };
  if (pts.size() < s.min_points) return too_few(pts.size(), "(disc and search band)");
  auto first = FitPlane(pts);
  if (!first.ok())
    return absl::InvalidArgumentError(what + ": " + std::string(first.status().message()));
  std::vector<Eigen::Vector3d> kept;
  for (std::size_t i = 0; i < pts.size(); ++i)
    if (std::abs(first->residuals[i]) <= s.band_mm) kept.push_back(pts[i]);
  if (kept.size() < s.min_points) return too_few(kept.size(), "after the band");
  auto fit = FitPlane(kept);
  if (!fit.ok())
    return absl::InvalidArgumentError(what + ": " + std::string(fit.status().message()));
  f.fit = *std::move(fit);
  f.kept = kept.size();
  std::size_t lo = 0, hi = 0;
  f.f_mm = TrimmedRange(f.fit.residuals, outlier_share, &lo, &hi, &f.left_out);
  const Eigen::Vector3d dp = kept[hi] - kept[lo];
  const double a1 = dp.dot(f.fit.axis1), a2 = dp.dot(f.fit.axis2);
  f.u_f_mm = std::hypot(std::sqrt(a1 * a1 * f.fit.tilt_variance1 + a2 * a2 * f.fit.tilt_variance2),
                        ExtremeResolution(f.fit.residuals, lo, hi));
  return f;
}

}  // namespace surfinspect
