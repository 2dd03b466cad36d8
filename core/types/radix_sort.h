// A stable LSD radix sort of (key, value) pairs with 11-bit digits: O(n) per
// pass, so a 31-bit key takes 3 passes. The link-clustering voxel grid sorts
// points by packed cell key with it, and the batch closest-point queries
// sort points by Morton code.
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

namespace surfinspect {

// Sorts keys[i] (each < 2^key_bits) ascending and permutes values alongside;
// equal keys keep their input order. keys and values have the same size.
// Polls `cancel` every 2^16 elements of each pass and returns false when it
// is set (the pairs are then in an unspecified order); true otherwise.
bool RadixSortPairs(std::vector<uint64_t>& keys, std::vector<uint32_t>& values, int key_bits,
                    const std::atomic<bool>* cancel = nullptr);

}  // namespace surfinspect
