// Whether any float of an array has given bits: one pass on the bits, with
// no branch per float, which the compiler vectorizes, so a cloud is checked
// at memory speed. The infinity check of PointCloud::Validate and the -0
// test of TransformKeepsCloud.
#pragma once

#include <cstddef>
#include <cstdint>

namespace surfinspect {

// True when (bits & mask) == value for any of the n floats at f.
bool AnyFloatWithBits(const float* f, std::size_t n, uint32_t mask, uint32_t value);

}  // namespace surfinspect
