// The visiting order of an unorganized cloud's batch query
// (mesh_index_batch.cpp): 30-bit Morton codes on a 1024^3 grid over the
// valid points' bounds, sorted by a stable radix sort, so that consecutive
// queries are near each other and each starts from the last one's answer.
#pragma once

#include <atomic>
#include <cstdint>

#include "core/types/default_init_vector.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

// The bounds and codes kernels' instruction set. kAuto takes AVX-512 (16
// points per instruction, morton_order_avx512.h) where the CPU has F and DQ,
// else the scalar loops; the codes, and so the order, are the same in each.
enum class MortonIsa { kAuto, kScalar, kAvx512 };
bool MortonIsaSupported(MortonIsa isa);

// code << 32 | point index for every point of `cloud` (at most 2^32 of
// them), in visiting order: ascending code, equal codes in input order, the
// invalid points last (code 2^30). Bounds, codes and the sort run on the
// calling task arena's threads, the same for any number of them. Empty when
// `cancel` is set. `isa` must be supported.
DefaultInitVector<uint64_t> MortonOrder(const PointCloud& cloud, const std::atomic<bool>* cancel,
                                        MortonIsa isa = MortonIsa::kAuto);

}  // namespace surfinspect
