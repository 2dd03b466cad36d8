#include "core/types/float_scan.h"

#include <cstring>

namespace surfinspect {

bool AnyFloatWithBits(const float* f, std::size_t n, uint32_t mask, uint32_t value) {
  uint32_t hit = 0;
  for (std::size_t i = 0; i < n; ++i) {
    uint32_t bits;
    std::memcpy(&bits, f + i, sizeof bits);
    hit |= static_cast<uint32_t>((bits & mask) == value);
  }
  return hit != 0;
}

}  // namespace surfinspect
