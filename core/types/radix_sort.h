// Stable radix sorts, O(n) per pass. The link-clustering voxel grid sorts
// points by packed cell key with the pair sort (LSD, 11-bit digits: three
// passes for a 31-bit key), and the batch closest-point queries sort points
// by Morton code with the packed one (below).
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

#include "core/types/default_init_vector.h"

namespace surfinspect {

// Sorts keys[i] (each < 2^key_bits) ascending and permutes values alongside;
// equal keys keep their input order. keys and values have the same size.
// Polls `cancel` every 2^16 elements of each pass and returns false when it
// is set (keys and values then hold unspecified contents); true otherwise.
bool RadixSortPairs(std::vector<uint64_t>& keys, std::vector<uint32_t>& values, int key_bits,
                    const std::atomic<bool>* cancel = nullptr);

// The same for pairs packed as key << 32 | value (key < 2^key_bits,
// key_bits <= 32), most significant digit first: one stable pass on the top
// 10 bits of the key over the whole array, in contiguous chunks on the
// calling task arena's threads (one chunk per thread, at least 2^16 items
// each), then each of its up to 1024 buckets by the rest of the key with
// 8-bit LSD passes, buckets in parallel; a pass whose digit every item
// shares is skipped. One pass over memory instead of three for a 30-bit
// Morton code; the order is the same for any number of threads, as the
// sort is stable. Polls `cancel` every 2^16 items of the first pass and
// before each bucket; returns false when it is set. A bucket that holds
// most items (a cloud whose points all share the top digit) is sorted by
// one thread.
bool RadixSortPacked(DefaultInitVector<uint64_t>& items, int key_bits,
                     const std::atomic<bool>* cancel = nullptr);

}  // namespace surfinspect
