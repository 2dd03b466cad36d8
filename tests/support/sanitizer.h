// What a test must know about a sanitized build (./run test --sanitize):
// AddressSanitizer replaces malloc, and sanitized code runs 2-5x slower, so
// timing bounds scale by kSanitizerSlowdown (1 in a normal build).
#pragma once

namespace surfinspect::testing {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kAddressSanitizer = true;
inline constexpr double kSanitizerSlowdown = 5.0;
#else
inline constexpr bool kAddressSanitizer = false;
inline constexpr double kSanitizerSlowdown = 1.0;
#endif

}  // namespace surfinspect::testing
