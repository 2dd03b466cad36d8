// The one percentile definition of the reports: NumPy's default "linear"
// rule. For n sorted values v[0..n-1] and q in [0, 1], with pos = q (n - 1),
//     P(q) = v[floor(pos)] + (pos - floor(pos)) (v[floor(pos) + 1] - v[floor(pos)]),
// and P(q) = v[n - 1] at the top. The error map's p1..p99 and the
// calibration's residual p50/p95/p99 both use it.
#pragma once

#include <cstddef>
#include <vector>

namespace surfinspect {

// Percentiles of one vector, by partial selection (O(n) per call, no full
// sort). Reorders the vector it is given; calls must come in increasing q,
// so each selection works only on the tail the previous one left.
template <typename T>
class Percentiles {
 public:
  explicit Percentiles(std::vector<T>& values) : v_(values) {}
  // P(q) as above; NaN for an empty vector.
  double At(double q);

 private:
  std::vector<T>& v_;
  std::size_t done_ = 0;
};

extern template class Percentiles<float>;
extern template class Percentiles<double>;

// The median of v: P(0.5) (the mean of the two middle values for an even
// count); reorders v. NaN when v is empty.
double MedianInPlace(std::vector<double>& v);

// The robust sigma of residuals from their absolute values: 1.4826 times
// their median (the MAD, scaled to a normal's standard deviation; Rousseeuw
// and Croux, JASA 88 (1993)). Reorders `abs_residuals`; NaN when empty.
double MadSigma(std::vector<double>& abs_residuals);

// P(q) for each q of `qs` (at most 100, each in [0, 1); NaN otherwise or
// for no values)
// over floats, leaving `values` as they are: one pass counts the values by
// the top 16 bits of an order-preserving key, a second gathers the few
// buckets that hold the ranks the q need, and a selection within those
// finishes. The results equal Percentiles<float>'s to the bit: the ranks
// pick the same numbers, and the only floats that compare equal with other
// bits, -0 and +0, come out of the interpolation as +0 either way (below
// q = 1, where P(1) would be the largest value itself).
std::vector<double> FloatPercentiles(const std::vector<float>& values,
                                     const std::vector<double>& qs);

}  // namespace surfinspect
