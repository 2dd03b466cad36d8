// The data section of a PLY file, one row at a time, after ply_format.h
// parsed the header. Every value is bounds-checked: an ascii row is one line
// whose values must all be numbers of their property's type (blank lines
// are skipped), a binary row must lie inside the buffer, and a list's length
// is checked against what is left before anything is read.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "core/io/ply_format.h"

namespace surfinspect {

// One value: its token (ascii) or its first byte (binary).
struct PlyValue {
  std::string_view text;
  const uint8_t* raw = nullptr;
};

// One row of an element: property p's values are values[first[p]] up to
// values[first[p + 1]] (a list's length prefix is not among them).
struct PlyRow {
  std::vector<PlyValue> values;
  std::vector<uint32_t> first;
};

class PlyRowReader {
 public:
  // `bytes` and `header` must outlive the reader.
  PlyRowReader(std::string_view bytes, const PlyHeader& header, std::string_view name);

  // Reads the next row of `element` (elements come in header order).
  absl::Status Next(const PlyElement& element, uint64_t row_index, PlyRow* row);
  // Reads past all rows of an element, checking them as Next does.
  absl::Status Skip(const PlyElement& element);
  // Binary only: the next `n` bytes, checked against the buffer's end.
  absl::Status TakeBytes(uint64_t n, const uint8_t** p);
  // Ascii rows are lines; ascii data can hold at most this many more rows.
  uint64_t RemainingBytes() const { return bytes_.size() - pos_; }

 private:
  absl::Status NextAscii(const PlyElement& element, uint64_t row_index, PlyRow* row);
  absl::Status NextBinary(const PlyElement& element, uint64_t row_index, PlyRow* row);
  absl::Status RowError(const PlyElement& element, uint64_t row_index, std::string_view why) const;

  std::string_view bytes_;
  const PlyHeader& header_;
  std::string_view name_;
  std::size_t pos_;
  std::vector<std::string_view> tokens_;
};

// The integer a value holds; false for a float type or (ascii) a token that
// is not an integer in its type's range.
bool PlyIntValue(PlyFormat format, PlyType type, const PlyValue& v, int64_t* out);
// A binary value as double (float32 and float64 exactly, integers exactly).
double PlyBinaryDouble(PlyFormat format, PlyType type, const uint8_t* raw);
// A binary float32 with its bits kept (NaN payloads included).
float PlyBinaryFloat32(PlyFormat format, const uint8_t* raw);

// All rows of `element` when they are little-endian rows of scalars whose
// x, y, z (properties prop[0..2]) are float32: copied straight from the
// buffer into `out`, bits and all, in one pass. False, with nothing read,
// for any other layout or a buffer too short for the rows, which the caller
// then reads row by row (or refuses) as usual.
bool TakeFloat32XyzRows(PlyRowReader* reader, const PlyHeader& header, const PlyElement& element,
                        const int prop[3], std::vector<Eigen::Vector3f>* out);

}  // namespace surfinspect
