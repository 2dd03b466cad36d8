// std::lround without the library call, for the hot loops that turn
// colours and pixel positions into integers.
#pragma once

#include <cstdint>

namespace surfinspect {

// The nearest integer, halves away from zero, as std::lround, for finite
// |v| < 2^52. t = trunc(v) and v shares t's binade (or t = 0), so v - t is
// exact (Sterbenz) and the comparisons with one half decide as lround does.
inline int64_t RoundHalfAwayFromZero(double v) {
  const auto t = static_cast<int64_t>(v);
  const double frac = v - static_cast<double>(t);
  return t + (frac >= 0.5) - (frac <= -0.5);
}

}  // namespace surfinspect
