#include "core/history/drift_line.h"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace surfinspect {
namespace {

// Continued fraction of the incomplete beta function, modified Lentz's
// method (Numerical Recipes, 3rd ed., eq. 6.4.5).
double BetaContinuedFraction(double a, double b, double x) {
  constexpr double kTiny = 1e-300;
  const double qab = a + b, qap = a + 1, qam = a - 1;
  double c = 1, d = 1 - qab * x / qap;
  d = 1 / (std::abs(d) < kTiny ? kTiny : d);
  double h = d;
  for (int m = 1; m <= 300; ++m) {
    const int m2 = 2 * m;
    double aa = m * (b - m) * x / ((qam + m2) * (a + m2));
    d = 1 + aa * d;
    d = 1 / (std::abs(d) < kTiny ? kTiny : d);
    c = 1 + aa / c;
    c = std::abs(c) < kTiny ? kTiny : c;
    h *= d * c;
    aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
    d = 1 + aa * d;
    d = 1 / (std::abs(d) < kTiny ? kTiny : d);
    c = 1 + aa / c;
    c = std::abs(c) < kTiny ? kTiny : c;
    const double del = d * c;
    h *= del;
    if (std::abs(del - 1) < 1e-15) break;
  }
  return h;
}

// I_x(a, b), the regularized incomplete beta function (eq. 6.4.1).
double RegularizedBeta(double a, double b, double x) {
  if (x <= 0) return 0;
  if (x >= 1) return 1;
  const double front = std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) +
                                a * std::log(x) + b * std::log1p(-x));
  if (x < (a + 1) / (a + b + 2)) return front * BetaContinuedFraction(a, b, x) / a;
  return 1 - front * BetaContinuedFraction(b, a, 1 - x) / b;
}

// P(T <= t) for Student's t with nu degrees of freedom (eq. 6.14.11). Near
// t = 0 the complement I_{t^2/(nu+t^2)}(1/2, nu/2) keeps its precision.
double StudentTCdf(double t, double nu) {
  const double t2 = t * t;
  const double tail = t2 < nu ? 0.5 * (1 - RegularizedBeta(0.5, nu / 2, t2 / (nu + t2)))
                              : 0.5 * RegularizedBeta(nu / 2, 0.5, nu / (nu + t2));
  return t >= 0 ? 1 - tail : tail;
}

}  // namespace

double StudentTQuantile(double p, double dof) {
  if (!(p > 0 && p < 1) || !(dof >= 1)) return NAN;
  double lo = -1e7, hi = 1e7;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * std::max(1.0, std::abs(lo)); ++i) {
    const double mid = 0.5 * (lo + hi);
    (StudentTCdf(mid, dof) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

absl::StatusOr<DriftLine> FitDriftLine(const std::vector<double>& y, double confidence) {
  if (y.size() < 3)
    return absl::InvalidArgumentError(
        absl::StrCat("a drift line needs at least 3 parts, got ", y.size()));
  if (!(confidence > 0 && confidence < 1))
    return absl::InvalidArgumentError(absl::StrCat("confidence ", confidence, " not in (0, 1)"));
  const double n = static_cast<double>(y.size());
  const double x_mean = (n - 1) / 2;
  double y_mean = 0;
  for (double v : y) y_mean += v;
  y_mean /= n;
  double sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    sxx += (i - x_mean) * (i - x_mean);
    sxy += (i - x_mean) * (y[i] - y_mean);
  }
  DriftLine line;
  line.confidence = confidence;
  line.slope_mm_per_part = sxy / sxx;
  line.intercept_mm = y_mean - line.slope_mm_per_part * x_mean;
  double sse = 0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    const double r = y[i] - (line.intercept_mm + line.slope_mm_per_part * i);
    sse += r * r;
  }
  line.slope_se_mm_per_part = std::sqrt(sse / (n - 2) / sxx);
  const double t = StudentTQuantile(1 - (1 - confidence) / 2, n - 2);
  line.ci_lower = line.slope_mm_per_part - t * line.slope_se_mm_per_part;
  line.ci_upper = line.slope_mm_per_part + t * line.slope_se_mm_per_part;
  return line;
}

}  // namespace surfinspect
