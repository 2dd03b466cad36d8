// The drift line of one characteristic: the least-squares line through its
// values against the part's position in the selection (0, 1, 2, ...), so the
// slope is in mm per part, with the slope's two-sided confidence interval.
//
// Montgomery & Runger, Applied Statistics and Probability for Engineers,
// 6th ed., sections 11-2 and 11-5.2:
//   b = Sxy / Sxx,  s^2 = SSE / (n - 2),  se(b) = sqrt(s^2 / Sxx),
//   CI = b -+ t(1 - alpha/2, n - 2) se(b).
#pragma once

#include <vector>

#include "absl/status/statusor.h"

namespace surfinspect {

struct DriftLine {
  double slope_mm_per_part = 0;
  double intercept_mm = 0;  // the fitted value at the first part
  double slope_se_mm_per_part = 0;
  double ci_lower = 0, ci_upper = 0;  // mm per part
  double confidence = 0.95;
};

// Needs at least 3 finite values; confidence in (0, 1).
absl::StatusOr<DriftLine> FitDriftLine(const std::vector<double>& values_mm,
                                       double confidence = 0.95);

// The p-quantile of Student's t with `dof` degrees of freedom (p in (0, 1),
// dof >= 1), by bisection on the CDF through the regularized incomplete beta
// function (Numerical Recipes, 3rd ed., sections 6.4 and 6.14.8). Good to 1e-10.
double StudentTQuantile(double p, double dof);

}  // namespace surfinspect
