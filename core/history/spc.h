// Statistical process control of one characteristic across parts: the
// capability indices and the limits of the individuals (X) and moving-range
// (MR) charts, for individual values in part order (mm).
//
// Formulas (Montgomery, Introduction to Statistical Quality Control, 7th ed.,
// sections 6.4 and 8.2):
//   MR_i = |x_i - x_{i-1}|,  sigma_within = MRbar / d2,  d2 = 1.128 (n = 2)
//   sigma_overall = the sample standard deviation (n - 1)
//   Cp = (USL - LSL) / (6 sigma_within),  Cpk = min(USL - mean, mean - LSL) / (3 sigma_within)
//   Pp, Ppk: the same with sigma_overall
//   X chart: mean +- 3 sigma_within;  MR chart: centre MRbar, UCL = D4 MRbar
//   (D4 = 3.267), LCL = 0 (D3 = 0).
// An index is NaN where it is undefined (a zero sigma).
#pragma once

#include <cstddef>
#include <vector>

#include "absl/status/statusor.h"

namespace surfinspect {

inline constexpr double kD2 = 1.128;  // E[range] / sigma for subgroups of 2
inline constexpr double kD4 = 3.267;  // MR chart's UCL factor for subgroups of 2

struct ControlLimits {
  double center = 0, lower = 0, upper = 0;  // mm
};

struct SpcResult {
  std::size_t n = 0;
  double mean_mm = 0;
  double mr_bar_mm = 0;  // mean moving range
  double sigma_within_mm = 0, sigma_overall_mm = 0;
  double cp = 0, cpk = 0, pp = 0, ppk = 0;
  ControlLimits individuals;             // X chart
  ControlLimits moving_range;            // MR chart
  std::vector<double> moving_ranges_mm;  // n - 1 values, MR_i for i = 1..n-1
};

// Needs at least 2 finite values and lower_mm < upper_mm; lower_mm may be
// -infinity (a one-sided tolerance: Cp and Pp NaN, Cpk and Ppk of the upper
// limit).
absl::StatusOr<SpcResult> ComputeSpc(const std::vector<double>& values_mm, double lower_mm,
                                     double upper_mm);

}  // namespace surfinspect
