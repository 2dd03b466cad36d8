// PLY (Stanford polygon format) parsed from a byte buffer by our own code,
// for clouds and meshes alike. The header is parsed strictly: the "ply"
// magic, one "format" line (ascii 1.0, binary_little_endian 1.0 or
// binary_big_endian 1.0), elements and their scalar or list properties of
// the eight PLY types, comments, and obj_info lines (num_cols / num_rows are
// read as the grid); anything else, a repeated element or property, or a
// bad number is refused. The row reader then walks the data section one row
// at a time with every value bounds-checked: an ascii row is one line whose
// values must all be numbers of their property's type, a binary row must
// lie inside the buffer, and a list's length is checked against what is
// left before anything is read.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"

namespace surfinspect {

enum class PlyFormat { kAscii, kBinaryLittleEndian, kBinaryBigEndian };
enum class PlyType : uint8_t {
  kInt8,
  kUint8,
  kInt16,
  kUint16,
  kInt32,
  kUint32,
  kFloat32,
  kFloat64
};

int PlyTypeSize(PlyType t);
bool PlyTypeIsInteger(PlyType t);

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;  // of the value, or of a list's items
  bool is_list = false;
  PlyType count_type = PlyType::kUint8;  // a list's length prefix
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> properties;
  int FindProperty(std::string_view property) const;  // -1 when absent
  // Bytes per binary row when the element has no list property.
  std::optional<uint64_t> FixedRowBytes() const;
};

struct PlyHeader {
  PlyFormat format = PlyFormat::kAscii;
  std::vector<PlyElement> elements;
  std::optional<uint64_t> num_cols, num_rows;       // obj_info num_cols / num_rows
  std::size_t data_offset = 0;                      // first byte after "end_header\n"
  int FindElement(std::string_view element) const;  // -1 when absent
};

// Errors are INVALID_ARGUMENT ("NAME: why"), RESOURCE_EXHAUSTED when an
// element declares more than `max_rows` rows.
absl::StatusOr<PlyHeader> ParsePlyHeader(std::string_view bytes, uint64_t max_rows,
                                         std::string_view name);

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

}  // namespace surfinspect
