#include "core/io/text_parse.h"

#include <cctype>
#include <fstream>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"

namespace surfinspect {

absl::Status BadFile(std::string_view name, absl::string_view why) {
  return absl::InvalidArgumentError(absl::StrCat(ToAbsl(name), ": ", why));
}

bool CheckedMul(uint64_t a, uint64_t b, uint64_t* out) {
  return !__builtin_mul_overflow(a, b, out);
}

bool CheckedAdd(uint64_t a, uint64_t b, uint64_t* out) {
  return !__builtin_add_overflow(a, b, out);
}

bool LineScanner::Next(std::string_view* line) {
  if (pos_ >= data_.size()) return false;
  const std::size_t end = data_.find('\n', pos_);
  const std::size_t stop = end == std::string_view::npos ? data_.size() : end;
  std::string_view l = data_.substr(pos_, stop - pos_);
  if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
  pos_ = end == std::string_view::npos ? data_.size() : end + 1;
  ++line_number_;
  *line = l;
  return true;
}

namespace {
bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }
}  // namespace

void SplitWhitespace(std::string_view line, std::vector<std::string_view>* tokens) {
  tokens->clear();
  std::size_t i = 0;
  const std::size_t n = line.size();
  while (i < n) {
    while (i < n && IsSpace(line[i])) ++i;
    const std::size_t start = i;
    while (i < n && !IsSpace(line[i])) ++i;
    if (i > start) tokens->push_back(line.substr(start, i - start));
  }
}

bool IsBlank(std::string_view line) {
  for (char c : line)
    if (!IsSpace(c)) return false;
  return true;
}

bool ParseUint(std::string_view s, uint64_t* out) {
  if (s.empty() || s.size() > 20) return false;
  uint64_t v = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
    if (!CheckedMul(v, 10, &v) || !CheckedAdd(v, static_cast<uint64_t>(c - '0'), &v)) return false;
  }
  *out = v;
  return true;
}

bool ParseInt(std::string_view s, int64_t* out) {
  bool negative = false;
  if (!s.empty() && (s[0] == '-' || s[0] == '+')) {
    negative = s[0] == '-';
    s.remove_prefix(1);
  }
  uint64_t magnitude = 0;
  if (!ParseUint(s, &magnitude)) return false;
  if (negative) {
    if (magnitude > uint64_t{1} << 63) return false;
    *out = magnitude == uint64_t{1} << 63 ? INT64_MIN : -static_cast<int64_t>(magnitude);
  } else {
    if (magnitude > static_cast<uint64_t>(INT64_MAX)) return false;
    *out = static_cast<int64_t>(magnitude);
  }
  return true;
}

namespace {
// absl's parsers skip surrounding whitespace and read hexadecimal; a token
// must be plain decimal.
bool PlainToken(std::string_view s) {
  return !s.empty() && !IsSpace(s.front()) && !IsSpace(s.back()) &&
         s.find_first_of("xX") == std::string_view::npos;
}
}  // namespace

bool ParseFloat(std::string_view s, float* out) {
  return PlainToken(s) && absl::SimpleAtof(ToAbsl(s), out);
}

bool ParseDouble(std::string_view s, double* out) {
  return PlainToken(s) && absl::SimpleAtod(ToAbsl(s), out);
}

absl::StatusOr<std::string> ReadWholeFile(const std::string& path, uint64_t max_bytes) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return absl::NotFoundError(absl::StrCat(path, ": cannot open"));
  const std::streamoff end = in.tellg();
  if (end < 0) return absl::NotFoundError(absl::StrCat(path, ": cannot read"));
  const auto size = static_cast<uint64_t>(end);
  if (size == 0) return BadFile(path, "file is empty");
  if (size > max_bytes)
    return absl::ResourceExhaustedError(absl::StrCat(path, ": file exceeds ", max_bytes, " bytes"));
  std::string bytes(size, '\0');
  in.seekg(0);
  if (!in.read(bytes.data(), static_cast<std::streamsize>(size)))
    return absl::DataLossError(absl::StrCat(path, ": short read"));
  return bytes;
}

std::string Excerpt(std::string_view s, std::size_t max_chars) {
  std::string out;
  for (char c : s.substr(0, max_chars))
    out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  if (s.size() > max_chars) out += "...";
  return out;
}

}  // namespace surfinspect
