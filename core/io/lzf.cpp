#include "core/io/lzf.h"

#include <algorithm>
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

namespace {

constexpr std::size_t kMaxLiteralRun = 32;      // control byte c < 32 means c + 1 bytes
constexpr std::size_t kMaxDistance = 1u << 13;  // 13 bits of distance - 1
constexpr std::size_t kMinMatch = 3;
constexpr std::size_t kMaxMatch = 7 + 255 + 2;
constexpr int kHashBits = 14;

uint32_t Hash3(const uint8_t* p) {
  const uint32_t v = uint32_t{p[0]} | uint32_t{p[1]} << 8 | uint32_t{p[2]} << 16;
  return (v * 2654435761u) >> (32 - kHashBits);  // Knuth's multiplicative hash
}

void PutLiterals(const uint8_t* from, std::size_t count, std::string& out) {
  while (count > 0) {
    const std::size_t run = std::min(count, kMaxLiteralRun);
    out.push_back(static_cast<char>(run - 1));
    out.append(reinterpret_cast<const char*>(from), run);
    from += run;
    count -= run;
  }
}

// A reference of `len` bytes (kMinMatch..kMaxMatch) from `distance` back.
void PutReference(std::size_t len, std::size_t distance, std::string& out) {
  const std::size_t l = len - 2, d = distance - 1;
  out.push_back(static_cast<char>((std::min<std::size_t>(l, 7) << 5) | (d >> 8)));
  if (l >= 7) out.push_back(static_cast<char>(l - 7));
  out.push_back(static_cast<char>(d & 0xff));
}

}  // namespace

std::string LzfCompress(std::string_view bytes) {
  const auto* in = reinterpret_cast<const uint8_t*>(bytes.data());
  const std::size_t n = bytes.size();
  std::string out;
  out.reserve(n + n / kMaxLiteralRun + 1);
  std::vector<uint32_t> last_at(std::size_t{1} << kHashBits, 0);  // position + 1; 0 = none
  std::size_t ip = 0, literals_from = 0;
  while (ip + kMinMatch <= n) {
    const uint32_t h = Hash3(in + ip);
    const std::size_t candidate = last_at[h];
    last_at[h] = static_cast<uint32_t>(ip + 1);
    if (candidate == 0 || ip + 1 - candidate > kMaxDistance ||
        std::memcmp(in + candidate - 1, in + ip, kMinMatch) != 0) {
      ++ip;
      continue;
    }
    const std::size_t from = candidate - 1;
    const std::size_t most = std::min(kMaxMatch, n - ip);
    std::size_t len = kMinMatch;
    while (len < most && in[from + len] == in[ip + len]) ++len;
    PutLiterals(in + literals_from, ip - literals_from, out);
    PutReference(len, ip - from, out);
    ip += len;
    literals_from = ip;
  }
  PutLiterals(in + literals_from, n - literals_from, out);
  return out;
}

}  // namespace surfinspect
