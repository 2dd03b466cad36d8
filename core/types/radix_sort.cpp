#include "core/types/radix_sort.h"

#include <algorithm>
#include <cstddef>
#include <utility>

#include "core/types/cancel.h"

namespace surfinspect {
namespace {

constexpr std::size_t kCancelStride = std::size_t{1} << 16;

// Where each digit's run starts after a stable pass on the digit at `shift`
// (an exclusive prefix sum of the digit counts).
template <typename Keys>
void DigitStarts(const Keys& keys, int shift, std::vector<std::size_t>& start) {
  const std::size_t mask = start.size() - 1;
  std::fill(start.begin(), start.end(), 0);
  for (uint64_t k : keys) ++start[(k >> shift) & mask];
  std::size_t sum = 0;
  for (auto& s : start) sum += std::exchange(s, sum);
}

}  // namespace

bool RadixSortPairs(std::vector<uint64_t>& keys, std::vector<uint32_t>& values, int key_bits,
                    const std::atomic<bool>* cancel) {
  constexpr int kDigitBits = 11;
  constexpr std::size_t kBuckets = std::size_t{1} << kDigitBits;
  if (key_bits <= 0) return !IsCancelled(cancel);
  std::vector<uint64_t> keys_tmp(keys.size());
  std::vector<uint32_t> values_tmp(values.size());
  std::vector<std::size_t> start(kBuckets);
  for (int shift = 0; shift < key_bits; shift += kDigitBits) {
    DigitStarts(keys, shift, start);
    for (std::size_t i = 0; i < keys.size(); ++i) {
      if (i % kCancelStride == 0 && IsCancelled(cancel)) return false;
      const std::size_t to = start[(keys[i] >> shift) & (kBuckets - 1)]++;
      keys_tmp[to] = keys[i];
      values_tmp[to] = values[i];
    }
    keys.swap(keys_tmp);
    values.swap(values_tmp);
  }
  return true;
}

bool RadixSortPacked(DefaultInitVector<uint64_t>& items, int key_bits,
                     const std::atomic<bool>* cancel) {
  // 10-bit digits: 1024 write positions stay in the L1 cache while a pass
  // scatters (with 11 bits a pass took about twice as long on 10^6 items here).
  constexpr int kDigitBits = 10;
  constexpr std::size_t kBuckets = std::size_t{1} << kDigitBits;
  if (key_bits <= 0) return !IsCancelled(cancel);
  key_bits = std::min(key_bits, 32);
  // Each pass writes every slot; its first touches the pages where it polls.
  DefaultInitVector<uint64_t> tmp(items.size());
  std::vector<std::size_t> start(kBuckets);
  for (int shift = 32; shift < 32 + key_bits; shift += kDigitBits) {
    DigitStarts(items, shift, start);
    for (std::size_t i = 0; i < items.size(); ++i) {
      if (i % kCancelStride == 0 && IsCancelled(cancel)) return false;
      tmp[start[(items[i] >> shift) & (kBuckets - 1)]++] = items[i];
    }
    items.swap(tmp);
  }
  return true;
}

}  // namespace surfinspect
