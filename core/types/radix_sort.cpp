#include "core/types/radix_sort.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <utility>

#include "core/types/cancel.h"

namespace surfinspect {
namespace {

// Where each digit's run starts after a stable pass on the digit at `shift`
// (an exclusive prefix sum of the digit counts).
void DigitStarts(const uint64_t* keys, std::size_t n, int shift, std::vector<std::size_t>& start) {
  const std::size_t mask = start.size() - 1;
  std::fill(start.begin(), start.end(), 0);
  for (std::size_t i = 0; i < n; ++i) ++start[(keys[i] >> shift) & mask];
  std::size_t sum = 0;
  for (auto& s : start) sum += std::exchange(s, sum);
}

}  // namespace

bool RadixSortPairs(std::vector<uint64_t>& keys, std::vector<uint32_t>& values, int key_bits,
                    const std::atomic<bool>* cancel) {
  constexpr int kDigitBits = 11;
  constexpr std::size_t kBuckets = std::size_t{1} << kDigitBits;
  if (key_bits <= 0) return !IsCancelled(cancel);
  const std::size_t n = keys.size();
  // Every pass writes every slot, so the scratch starts unwritten: its pages
  // are first touched in the first pass, which polls, instead of in a
  // serial zeroing that cannot (core/types/default_init_vector.h).
  DefaultInitVector<uint64_t> keys_tmp(n);
  DefaultInitVector<uint32_t> values_tmp(n);
  uint64_t *from_keys = keys.data(), *to_keys = keys_tmp.data();
  uint32_t *from_values = values.data(), *to_values = values_tmp.data();
  std::vector<std::size_t> start(kBuckets);
  for (int shift = 0; shift < key_bits; shift += kDigitBits) {
    DigitStarts(from_keys, n, shift, start);
    for (std::size_t i = 0; i < n; ++i) {
      if (CancelledAt(i, cancel)) return false;
      const std::size_t to = start[(from_keys[i] >> shift) & (kBuckets - 1)]++;
      to_keys[to] = from_keys[i];
      to_values[to] = from_values[i];
    }
    std::swap(from_keys, to_keys);
    std::swap(from_values, to_values);
  }
  // After an odd number of passes the sorted pairs are in the scratch.
  if (from_keys != keys.data()) {
    std::copy(from_keys, from_keys + n, keys.data());
    std::copy(from_values, from_values + n, values.data());
  }
  return true;
}

namespace {

// 10-bit digits: a chunk's 1024 write positions stay in the L1 cache while
// it scatters (with 11 bits a pass took about twice as long on 10^6 items).
constexpr int kPackedDigitBits = 10;
constexpr std::size_t kPackedBuckets = std::size_t{1} << kPackedDigitBits;

// Contiguous chunks of a packed pass: one per thread of the calling arena,
// with at least 2^16 items each.
std::size_t PassChunks(std::size_t n) {
  const auto threads = static_cast<std::size_t>(tbb::this_task_arena::max_concurrency());
  return std::max<std::size_t>(1, std::min(threads, n >> 16));
}

// cursor[c * kPackedBuckets + d]: where chunk c writes its first item of
// digit d, so that the pass is stable (digits in order, and within a digit
// the chunks in order); chunk 0's cursors are where the digits start. False
// when one digit holds every item: the pass would move nothing.
bool ChunkCursors(const DefaultInitVector<uint64_t>& items, int shift, std::size_t chunks,
                  std::vector<std::size_t>& cursor) {
  const std::size_t n = items.size(), per = (n + chunks - 1) / chunks;
  tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
    std::size_t* count = &cursor[c * kPackedBuckets];
    std::fill(count, count + kPackedBuckets, 0);
    for (std::size_t i = c * per; i < std::min(n, (c + 1) * per); ++i)
      ++count[(items[i] >> shift) & (kPackedBuckets - 1)];
  });
  std::size_t sum = 0;
  bool moves = true;
  for (std::size_t d = 0; d < kPackedBuckets; ++d) {
    const std::size_t digit_start = sum;
    for (std::size_t c = 0; c < chunks; ++c)
      sum += std::exchange(cursor[c * kPackedBuckets + d], sum);
    if (sum - digit_start == n) moves = false;
  }
  return moves;
}

// The stable pass on the digit at `shift`, chunks in parallel, into `to`.
// False when cancelled.
bool ScatterChunks(const DefaultInitVector<uint64_t>& items, int shift, std::size_t chunks,
                   std::vector<std::size_t>& cursor, DefaultInitVector<uint64_t>& to,
                   const std::atomic<bool>* cancel) {
  const std::size_t n = items.size(), per = (n + chunks - 1) / chunks;
  std::atomic<bool> stopped{false};
  tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
    std::size_t* next = &cursor[c * kPackedBuckets];
    for (std::size_t i = c * per; i < std::min(n, (c + 1) * per); ++i) {
      if (CancelledAt(i, cancel)) {
        stopped.store(true, std::memory_order_relaxed);
        return;
      }
      to[next[(items[i] >> shift) & (kPackedBuckets - 1)]++] = items[i];
    }
  });
  return !stopped.load();
}

// LSD passes of 8-bit digits over key bits [0, low_bits) of the m items at
// `a`, with `b` as scratch; the sorted items end at `a`. A bucket of the top
// digit is usually small enough that these passes run in cache.
void SortLowBits(uint64_t* a, uint64_t* b, std::size_t m, int low_bits) {
  constexpr int kBits = 8;
  constexpr std::size_t kDigits = std::size_t{1} << kBits;
  std::array<std::size_t, kDigits> start;
  uint64_t *from = a, *to = b;
  for (int shift = 32; shift < 32 + low_bits; shift += kBits) {
    start.fill(0);
    for (std::size_t i = 0; i < m; ++i) ++start[(from[i] >> shift) & (kDigits - 1)];
    if (*std::max_element(start.begin(), start.end()) == m) continue;  // nothing would move
    std::size_t sum = 0;
    for (auto& s : start) sum += std::exchange(s, sum);
    for (std::size_t i = 0; i < m; ++i) to[start[(from[i] >> shift) & (kDigits - 1)]++] = from[i];
    std::swap(from, to);
  }
  if (from != a) std::copy(from, from + m, a);
}

}  // namespace

bool RadixSortPacked(DefaultInitVector<uint64_t>& items, int key_bits,
                     const std::atomic<bool>* cancel) {
  if (key_bits <= 0) return !IsCancelled(cancel);
  key_bits = std::min(key_bits, 32);
  const int low_bits = std::max(0, key_bits - kPackedDigitBits);
  const std::size_t n = items.size(), chunks = PassChunks(n);
  // Each pass writes every slot; its first touches the pages where it polls.
  DefaultInitVector<uint64_t> tmp(n);
  std::vector<std::size_t> cursor(chunks * kPackedBuckets);
  if (IsCancelled(cancel)) return false;
  // Most significant digit first, over the whole array: it splits the items
  // into up to 1024 buckets, [bucket[d], bucket[d + 1]).
  const bool moves = ChunkCursors(items, 32 + low_bits, chunks, cursor);
  std::vector<std::size_t> bucket(cursor.begin(), cursor.begin() + kPackedBuckets);
  bucket.push_back(n);
  if (moves) {
    if (!ScatterChunks(items, 32 + low_bits, chunks, cursor, tmp, cancel)) return false;
    items.swap(tmp);
  }
  if (low_bits == 0) return true;
  // Then each bucket by the rest of the key, buckets in parallel.
  std::atomic<bool> stopped{false};
  tbb::parallel_for(std::size_t{0}, kPackedBuckets, [&](std::size_t d) {
    if (IsCancelled(cancel)) stopped.store(true, std::memory_order_relaxed);
    if (stopped.load(std::memory_order_relaxed) || bucket[d + 1] - bucket[d] < 2) return;
    SortLowBits(items.data() + bucket[d], tmp.data() + bucket[d], bucket[d + 1] - bucket[d],
                low_bits);
  });
  return !stopped.load();
}

}  // namespace surfinspect
