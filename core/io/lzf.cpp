#include "core/io/lzf.h"

#include <cstring>

#include "absl/strings/str_cat.h"

namespace surfinspect {

// Token layout (liblzf lzf_d.c): a control byte c < 32 starts a literal run
// of c + 1 bytes; otherwise len = c >> 5 (7 means "add the next byte"), and
// the back reference copies len + 2 bytes from distance
// ((c & 0x1f) << 8) + next byte + 1 behind the output position.
absl::StatusOr<std::vector<uint8_t>> LzfDecompress(std::string_view compressed,
                                                   uint64_t decoded_size) {
  if (decoded_size / kLzfMaxExpansion > compressed.size())
    return absl::InvalidArgumentError(
        absl::StrCat("LZF block of ", compressed.size(), " bytes cannot decode to ", decoded_size));
  std::vector<uint8_t> out(decoded_size);
  const auto* in = reinterpret_cast<const uint8_t*>(compressed.data());
  const std::size_t in_size = compressed.size();
  std::size_t ip = 0, op = 0;
  while (ip < in_size) {
    const unsigned ctrl = in[ip++];
    if (ctrl < 32) {
      const std::size_t len = ctrl + 1;
      if (len > in_size - ip)
        return absl::InvalidArgumentError("LZF literal run passes the end of its block");
      if (len > decoded_size - op)
        return absl::InvalidArgumentError(
            absl::StrCat("LZF block decodes past its declared size of ", decoded_size, " bytes"));
      std::memcpy(out.data() + op, in + ip, len);
      ip += len;
      op += len;
      continue;
    }
    std::size_t len = ctrl >> 5;
    if (len == 7) {
      if (ip >= in_size) return absl::InvalidArgumentError("LZF block ends inside a reference");
      len += in[ip++];
    }
    if (ip >= in_size) return absl::InvalidArgumentError("LZF block ends inside a reference");
    const std::size_t distance = ((ctrl & 0x1fu) << 8) + in[ip++] + 1;
    len += 2;
    if (distance > op)
      return absl::InvalidArgumentError("LZF back reference points before the block's start");
    if (len > decoded_size - op)
      return absl::InvalidArgumentError(
          absl::StrCat("LZF block decodes past its declared size of ", decoded_size, " bytes"));
    // Byte by byte: a reference may overlap the bytes it produces.
    for (std::size_t k = 0; k < len; ++k, ++op) out[op] = out[op - distance];
  }
  if (op != decoded_size)
    return absl::InvalidArgumentError(
        absl::StrCat("LZF block decodes to ", op, " bytes, not its declared ", decoded_size));
  return out;
}

}  // namespace surfinspect
