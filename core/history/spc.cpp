#include "core/history/spc.h"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace surfinspect {
namespace {

double Index(double numerator, double sigma) { return sigma > 0 ? numerator / sigma : NAN; }

}  // namespace

absl::StatusOr<SpcResult> ComputeSpc(const std::vector<double>& x, double lower_mm,
                                     double upper_mm) {
  if (x.size() < 2)
    return absl::InvalidArgumentError(absl::StrCat("SPC needs at least 2 parts, got ", x.size()));
  for (double v : x)
    if (!std::isfinite(v)) return absl::InvalidArgumentError("SPC values must be finite");
  if (!(lower_mm < upper_mm))
    return absl::InvalidArgumentError(
        absl::StrCat("SPC tolerance [", lower_mm, ", ", upper_mm, "] mm is empty"));
  SpcResult r;
  r.n = x.size();
  double sum = 0;
  for (double v : x) sum += v;
  r.mean_mm = sum / r.n;
  double ss = 0;
  for (double v : x) ss += (v - r.mean_mm) * (v - r.mean_mm);
  r.sigma_overall_mm = std::sqrt(ss / (r.n - 1));
  double mr_sum = 0;
  for (std::size_t i = 1; i < r.n; ++i) {
    r.moving_ranges_mm.push_back(std::abs(x[i] - x[i - 1]));
    mr_sum += r.moving_ranges_mm.back();
  }
  r.mr_bar_mm = mr_sum / (r.n - 1);
  r.sigma_within_mm = r.mr_bar_mm / kD2;
  // A one-sided tolerance (lower -infinity: a true position) has no Cp or
  // Pp; its Cpk and Ppk are the upper side's alone (Montgomery 8.2, the one-sided Cpu).
  const double width = std::isfinite(lower_mm) ? upper_mm - lower_mm : NAN;
  const double nearest = std::min(upper_mm - r.mean_mm, r.mean_mm - lower_mm);
  r.cp = Index(width, 6 * r.sigma_within_mm);
  r.cpk = Index(nearest, 3 * r.sigma_within_mm);
  r.pp = Index(width, 6 * r.sigma_overall_mm);
  r.ppk = Index(nearest, 3 * r.sigma_overall_mm);
  r.individuals = {r.mean_mm, r.mean_mm - 3 * r.sigma_within_mm, r.mean_mm + 3 * r.sigma_within_mm};
  r.moving_range = {r.mr_bar_mm, 0.0, kD4 * r.mr_bar_mm};
  return r;
}

}  // namespace surfinspect
