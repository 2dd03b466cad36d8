// The cancellation flag every long core loop polls: null means "cannot be
// cancelled". The server raises it from gRPC's OnCancel; loops poll it often
// enough that a cancelled call stops within milliseconds.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <vector>

namespace surfinspect {

inline bool IsCancelled(const std::atomic<bool>* cancel) {
  return cancel != nullptr && cancel->load(std::memory_order_relaxed);
}

// Per-item passes poll every this many items: at up to a few hundred ns an
// item, a cancelled call on 10^7 points stops within milliseconds.
constexpr std::size_t kCancelStride = std::size_t{1} << 16;

// IsCancelled at every kCancelStride-th item `i` of a pass; false between.
inline bool CancelledAt(std::size_t i, const std::atomic<bool>* cancel) {
  return i % kCancelStride == 0 && IsCancelled(cancel);
}

// Sets `v` to n copies of `value`, written slice by slice with `cancel`
// polled between slices; false (and `v` partly filled) when cancelled. A
// fresh buffer's first touch costs a page fault per 4 KiB, so one
// std::vector::assign of a 10^7-point result runs longer than a cancelled
// call may.
template <typename T>
bool FillUnlessCancelled(std::vector<T>& v, std::size_t n, const T& value,
                         const std::atomic<bool>* cancel) {
  constexpr std::size_t kSlice = std::size_t{1} << 18;
  v.clear();
  v.reserve(n);
  for (std::size_t i = 0; i < n; i += kSlice) {
    if (IsCancelled(cancel)) return false;
    v.insert(v.end(), std::min(kSlice, n - i), value);
  }
  return true;
}

}  // namespace surfinspect
