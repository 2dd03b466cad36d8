// Whether any float of an array has given bits: one pass on the bits, with
// no branch per float, which the compiler vectorizes, so a cloud is checked
// at memory speed; a large array is split over the calling arena's threads
// (a 10^6-point cloud alone on one core of this project's VMs: about
// 2.5 ms, bound by the memory bandwidth one core gets).
#pragma once

#include <cstddef>
#include <cstdint>

namespace surfinspect {

// True when (bits & mask) == value for any of the n floats at f.
bool AnyFloatWithBits(const float* f, std::size_t n, uint32_t mask, uint32_t value);

}  // namespace surfinspect
