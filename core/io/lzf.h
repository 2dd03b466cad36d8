// LZF (Marc Lehmann's liblzf format, used by PCD's binary_compressed
// encoding). The decoder is written to refuse rather than trust: every
// literal run and back reference is checked against the input's end, the
// output's declared size and the bytes already produced. The encoder is a
// greedy single-probe hash matcher; its stream is valid LZF, though not
// byte-identical to liblzf's own encoder.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"

namespace surfinspect {

// The most bytes one LZF input byte can expand to: a long back reference
// spends 3 bytes for at most 7 + 255 + 2 = 264 output bytes.
inline constexpr uint64_t kLzfMaxExpansion = 88;

// Decodes `compressed` into exactly `decoded_size` bytes. Fails (with a
// message that says why, no file name) when the stream decodes past that
// size, ends short of it, ends inside a token or refers before its start.
absl::StatusOr<std::vector<uint8_t>> LzfDecompress(std::string_view compressed,
                                                   uint64_t decoded_size);

// Encodes `bytes`. Never fails; incompressible input grows by at most one
// byte in 32 (a literal run's control byte), plus one.
std::string LzfCompress(std::string_view bytes);

}  // namespace surfinspect
