// PLY (Stanford polygon format) parsed from a byte buffer by our own code,
// for clouds and meshes alike. The header is parsed strictly: the "ply"
// magic, one "format" line (ascii 1.0, binary_little_endian 1.0 or
// binary_big_endian 1.0), elements and their scalar or list properties of
// the eight PLY types, comments, and obj_info lines (num_cols / num_rows are
// read as the grid); anything else, a repeated element or property, or a
// bad number is refused. ply_rows.h then walks the data section.
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

}  // namespace surfinspect
