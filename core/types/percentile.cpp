#include "core/types/percentile.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

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

double MedianInPlace(std::vector<double>& v) { return Percentiles<double>(v).At(0.5); }

double MadSigma(std::vector<double>& abs_residuals) {
  return 1.4826 * MedianInPlace(abs_residuals);
}

namespace {

// Orders as the floats do (-0 just below +0; no NaN among the values).
uint32_t OrderKey(float f) {
  uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  return (bits & 0x80000000u) ? ~bits : (bits | 0x80000000u);
}

constexpr int kBucketShift = 16;
constexpr std::size_t kBuckets = std::size_t{1} << (32 - kBucketShift);
constexpr uint8_t kNoSlot = 255;

// The values of the given ranks (each < values.size(), at most 254 of them).
std::vector<float> ValuesAtRanks(const std::vector<float>& values,
                                 const std::vector<std::size_t>& ranks) {
  std::vector<std::size_t> start(kBuckets + 1, 0);
  for (float f : values) ++start[(OrderKey(f) >> kBucketShift) + 1];
  for (std::size_t b = 0; b < kBuckets; ++b) start[b + 1] += start[b];
  // The bucket of each rank, and a gathering slot for each such bucket.
  std::vector<uint8_t> slot_of(kBuckets, kNoSlot);
  std::vector<std::size_t> bucket_of(ranks.size());
  std::vector<std::vector<float>> gathered;
  for (std::size_t i = 0; i < ranks.size(); ++i) {
    const auto it = std::upper_bound(start.begin(), start.end(), ranks[i]);
    bucket_of[i] = static_cast<std::size_t>(it - start.begin()) - 1;
    if (slot_of[bucket_of[i]] == kNoSlot) {
      slot_of[bucket_of[i]] = static_cast<uint8_t>(gathered.size());
      gathered.emplace_back();
      gathered.back().reserve(start[bucket_of[i] + 1] - start[bucket_of[i]]);
    }
  }
  for (float f : values) {
    const uint8_t slot = slot_of[OrderKey(f) >> kBucketShift];
    if (slot != kNoSlot) gathered[slot].push_back(f);
  }
  std::vector<float> out(ranks.size());
  for (std::size_t i = 0; i < ranks.size(); ++i) {
    std::vector<float>& in_bucket = gathered[slot_of[bucket_of[i]]];
    const auto k = static_cast<std::ptrdiff_t>(ranks[i] - start[bucket_of[i]]);
    std::nth_element(in_bucket.begin(), in_bucket.begin() + k, in_bucket.end());
    out[i] = in_bucket[static_cast<std::size_t>(k)];
  }
  return out;
}

}  // namespace

std::vector<double> FloatPercentiles(const std::vector<float>& values,
                                     const std::vector<double>& qs) {
  std::vector<double> out(qs.size(), NAN);
  const std::size_t n = values.size();
  if (n == 0 || qs.size() > 100) return out;
  std::vector<std::size_t> ranks;  // lo and, below the top, lo + 1 for each q
  for (double q : qs) {
    if (!(q >= 0 && q < 1)) continue;
    const auto lo = static_cast<std::size_t>(q * static_cast<double>(n - 1));
    ranks.push_back(lo);
    if (lo + 1 < n) ranks.push_back(lo + 1);
  }
  const std::vector<float> at = ValuesAtRanks(values, ranks);
  std::size_t next = 0;
  for (std::size_t i = 0; i < qs.size(); ++i) {
    if (!(qs[i] >= 0 && qs[i] < 1)) continue;
    const double pos = qs[i] * static_cast<double>(n - 1);
    const double a = at[next++];
    if (ranks[next - 1] + 1 >= n) {
      out[i] = a;
      continue;
    }
    const double b = at[next++];
    out[i] = a + (pos - static_cast<double>(ranks[next - 2])) * (b - a);
  }
  return out;
}

}  // namespace surfinspect
