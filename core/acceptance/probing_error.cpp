#include "core/acceptance/probing_error.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "absl/strings/str_format.h"

namespace surfinspect {
namespace {

std::vector<Eigen::Vector3d> Near(const PointCloud& cloud, const Eigen::Vector3d& c, double r) {
  std::vector<Eigen::Vector3d> out;
  cloud.ForEachValid([&](std::size_t, const Eigen::Vector3f& p) {
    const Eigen::Vector3d q = p.cast<double>();
    if ((q - c).squaredNorm() <= r * r) out.push_back(q);
  });
  return out;
}

}  // namespace

double TrimmedRange(const std::vector<double>& res, double share, std::size_t* lo, std::size_t* hi,
                    std::size_t* left_out) {
  std::vector<std::size_t> order(res.size());
  std::iota(order.begin(), order.end(), 0);
  const std::size_t drop = std::min<std::size_t>(
      res.size() > 0 ? res.size() - 1 : 0, std::size_t(std::ceil(share * double(res.size()))));
  // Largest |residual| last; ties to the higher index so the result is stable.
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const double ra = std::abs(res[a]), rb = std::abs(res[b]);
    return ra != rb ? ra < rb : a < b;
  });
  order.resize(order.size() - drop);
  *left_out = drop;
  *lo = *hi = order.empty() ? 0 : order.front();
  for (std::size_t i : order) {
    if (res[i] < res[*lo]) *lo = i;
    if (res[i] > res[*hi]) *hi = i;
  }
  return order.empty() ? 0.0 : res[*hi] - res[*lo];
}

double ExtremeResolution(const std::vector<double>& res, std::size_t lo, std::size_t hi) {
  if (res.size() < 2) return 0.0;
  std::vector<double> sorted = res;
  std::sort(sorted.begin(), sorted.end());
  const auto gap = [&](double v) {
    const auto it = std::lower_bound(sorted.begin(), sorted.end(), v);
    const std::size_t k = std::size_t(it - sorted.begin());
    double sum = 0;
    int n = 0;
    if (k > 0) sum += v - sorted[k - 1], ++n;
    if (k + 1 < sorted.size()) sum += sorted[k + 1] - v, ++n;
    return n > 0 ? sum / n : 0.0;
  };
  return std::hypot(gap(res[lo]), gap(res[hi]));
}

absl::StatusOr<ProbingError> MeasureSphere(const PointCloud& cloud, const SphereSearch& s,
                                           double outlier_share, const std::string& what) {
  if (!(s.diameter_mm > 0) || !(s.search_mm > 0) || !(s.band_mm > 0))
    return absl::InvalidArgumentError(what + ": diameter, search and band must be > 0");
  const Eigen::Vector3d& hint = s.centre_hint_mm;
  const double r = 0.5 * s.diameter_mm;
  ProbingError e;
  std::vector<Eigen::Vector3d> pts = Near(cloud, hint, r + s.search_mm);
  e.candidates = pts.size();
  if (pts.size() < s.min_points)
    return absl::NotFoundError(absl::StrFormat(
        "%s: %d points within %.1f mm of (%.2f, %.2f, %.2f) (at least %d needed): the sphere is "
        "not in the scan",
        what, pts.size(), r + s.search_mm, hint.x(), hint.y(), hint.z(), s.min_points));
  auto first = FitSphere(pts);
  if (!first.ok())
    return absl::InvalidArgumentError(what + ": " + std::string(first.status().message()));
  if (std::abs(first->radius - r) > s.search_mm || (first->centre - hint).norm() > s.search_mm)
    return absl::NotFoundError(absl::StrFormat(
        "%s: the points near (%.2f, %.2f, %.2f) fit a sphere of diameter %.3f mm at %.2f mm from "
        "the hint, not the %.3f mm sphere: the sphere is not in the scan",
        what, hint.x(), hint.y(), hint.z(), 2 * first->radius, (first->centre - hint).norm(),
        s.diameter_mm));
  std::vector<Eigen::Vector3d> kept;
  for (std::size_t i = 0; i < pts.size(); ++i)
    if (std::abs(first->residuals[i]) <= s.band_mm) kept.push_back(pts[i]);
  if (kept.size() < s.min_points)
    return absl::NotFoundError(absl::StrFormat("%s: only %d points within %.2f mm of the sphere",
                                               what, kept.size(), s.band_mm));
  auto fit = FitSphere(kept);
  if (!fit.ok())
    return absl::InvalidArgumentError(what + ": " + std::string(fit.status().message()));
  e.fit = *std::move(fit);
  e.kept = kept.size();
  std::size_t lo = 0, hi = 0;
  e.pf_mm = TrimmedRange(e.fit.residuals, outlier_share, &lo, &hi, &e.left_out);
  // d res_i = -n_i . dc - dr, so d PF = -(n_hi - n_lo) . dc.
  const Eigen::Vector3d dn =
      (kept[hi] - e.fit.centre).normalized() - (kept[lo] - e.fit.centre).normalized();
  e.centre_covariance = e.fit.covariance.topLeftCorner<3, 3>();
  e.u_pf_mm = std::hypot(std::sqrt(std::max(0.0, dn.dot(e.centre_covariance * dn))),
                         ExtremeResolution(e.fit.residuals, lo, hi));
  e.diameter_mm = 2 * e.fit.radius;
  e.ps_mm = e.diameter_mm - s.diameter_mm;
  e.u_ps_mm = 2 * std::sqrt(std::max(0.0, e.fit.covariance(3, 3)));
  return e;
}

}  // namespace surfinspect
