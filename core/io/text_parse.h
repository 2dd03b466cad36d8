// Small strict parsing helpers shared by the file readers: line and token
// scanning over a byte buffer, numbers that must be wholly numeric, and
// overflow-checked size arithmetic. Nothing here allocates from a count it
// has not checked.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace surfinspect {

// `name: why` as INVALID_ARGUMENT, the readers' one error shape.
absl::Status BadFile(std::string_view name, absl::string_view why);

inline absl::string_view ToAbsl(std::string_view s) { return {s.data(), s.size()}; }

// a * b and a + b, false on uint64 overflow.
bool CheckedMul(uint64_t a, uint64_t b, uint64_t* out);
bool CheckedAdd(uint64_t a, uint64_t b, uint64_t* out);

// Walks `data` line by line. A line ends at '\n' (not included); a trailing
// '\r' is dropped. The last line may lack its '\n'.
class LineScanner {
 public:
  explicit LineScanner(std::string_view data, std::size_t start = 0) : data_(data), pos_(start) {}
  bool Next(std::string_view* line);
  std::size_t pos() const { return pos_; }  // offset just after the last line read
  std::size_t line_number() const { return line_number_; }

 private:
  std::string_view data_;
  std::size_t pos_;
  std::size_t line_number_ = 0;
};

// Splits on spaces, tabs, '\r', '\v' and '\f' (runs count once).
void SplitWhitespace(std::string_view line, std::vector<std::string_view>* tokens);
bool IsBlank(std::string_view line);

// Decimal digits only (no sign, no spaces), no overflow.
bool ParseUint(std::string_view s, uint64_t* out);
// An optional '-' or '+' then decimal digits, within int64.
bool ParseInt(std::string_view s, int64_t* out);
// A decimal floating-point number, "inf"/"infinity"/"nan" (any case, with a
// sign) included, correctly rounded; out-of-range magnitudes become +-inf.
bool ParseFloat(std::string_view s, float* out);
bool ParseDouble(std::string_view s, double* out);

// The whole file. NOT_FOUND when it cannot be opened, INVALID_ARGUMENT
// "NAME: file is empty", RESOURCE_EXHAUSTED when larger than `max_bytes`.
absl::StatusOr<std::string> ReadWholeFile(const std::string& path, uint64_t max_bytes);

// Prints a short excerpt of untrusted text for an error message.
std::string Excerpt(std::string_view s, std::size_t max_chars = 40);

}  // namespace surfinspect
