#include "core/types/percentile.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace surfinspect {

template <typename T>
double Percentiles<T>::At(double q) {
  if (v_.empty()) return NAN;
  const double pos = q * static_cast<double>(v_.size() - 1);
  const auto lo = static_cast<std::size_t>(pos);
  std::nth_element(v_.begin() + static_cast<std::ptrdiff_t>(done_),
                   v_.begin() + static_cast<std::ptrdiff_t>(lo), v_.end());
  done_ = lo;
  const double a = v_[lo];
  if (lo + 1 >= v_.size()) return a;
  const double b = *std::min_element(v_.begin() + static_cast<std::ptrdiff_t>(lo + 1), v_.end());
  return a + (pos - static_cast<double>(lo)) * (b - a);
}

template class Percentiles<float>;
template class Percentiles<double>;

}  // namespace surfinspect
