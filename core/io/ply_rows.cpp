#include "core/io/ply_rows.h"

#include <cstring>
#include <optional>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/io/text_parse.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

// A token an ascii float property may hold (parsed fully by the consumer).
bool LooksNumeric(std::string_view t) {
  if (!t.empty() && (t[0] == '-' || t[0] == '+')) t.remove_prefix(1);
  if (t.empty()) return false;
  if (t[0] == 'i' || t[0] == 'I' || t[0] == 'n' || t[0] == 'N') {
    std::string lower;
    for (char c : t) lower += static_cast<char>(c | 0x20);
    return lower == "inf" || lower == "infinity" || lower == "nan";
  }
  bool digit = false;
  for (char c : t) {
    if (c >= '0' && c <= '9') {
      digit = true;
    } else if (c != '.' && c != 'e' && c != 'E' && c != '-' && c != '+') {
      return false;
    }
  }
  return digit;
}

bool InRange(PlyType t, int64_t v) {
  switch (t) {
    case PlyType::kInt8:
      return v >= -128 && v <= 127;
    case PlyType::kUint8:
      return v >= 0 && v <= 255;
    case PlyType::kInt16:
      return v >= -32768 && v <= 32767;
    case PlyType::kUint16:
      return v >= 0 && v <= 65535;
    case PlyType::kInt32:
      return v >= INT32_MIN && v <= INT32_MAX;
    case PlyType::kUint32:
      return v >= 0 && v <= int64_t{UINT32_MAX};
    default:
      return false;
  }
}

bool AsciiValueOk(PlyType t, std::string_view tok) {
  int64_t v;
  return PlyTypeIsInteger(t) ? ParseInt(tok, &v) && InRange(t, v) : LooksNumeric(tok);
}

template <typename T>
T Load(const uint8_t* p, bool big_endian) {
  uint8_t b[sizeof(T)];
  std::memcpy(b, p, sizeof(T));
  if (big_endian)
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
  T v;
  std::memcpy(&v, b, sizeof(T));
  return v;
}

}  // namespace

PlyRowReader::PlyRowReader(std::string_view bytes, const PlyHeader& header, std::string_view name)
    : bytes_(bytes), header_(header), name_(name), pos_(header.data_offset) {}

absl::Status PlyRowReader::RowError(const PlyElement& element, uint64_t row_index,
                                    std::string_view why) const {
  return BadFile(name_, absl::StrCat(Excerpt(element.name), " ", row_index, ": ", ToAbsl(why)));
}

absl::Status PlyRowReader::Next(const PlyElement& element, uint64_t row_index, PlyRow* row) {
  row->values.clear();
  row->first.clear();
  return header_.format == PlyFormat::kAscii ? NextAscii(element, row_index, row)
                                             : NextBinary(element, row_index, row);
}

absl::Status PlyRowReader::NextAscii(const PlyElement& element, uint64_t row_index, PlyRow* row) {
  LineScanner lines(bytes_, pos_);
  std::string_view line;
  do {
    if (!lines.Next(&line))
      return BadFile(name_, absl::StrCat("truncated: element ", Excerpt(element.name), " declares ",
                                         element.count, " rows, ", row_index, " found"));
  } while (IsBlank(line));
  pos_ = lines.pos();
  SplitWhitespace(line, &tokens_);
  std::size_t t = 0;
  for (const PlyProperty& p : element.properties) {
    row->first.push_back(static_cast<uint32_t>(row->values.size()));
    uint64_t n = 1;
    if (p.is_list) {
      int64_t len = 0;
      if (t >= tokens_.size() || !ParseInt(tokens_[t], &len) || !InRange(p.count_type, len))
        return RowError(element, row_index, absl::StrCat("bad list length for ", p.name));
      n = static_cast<uint64_t>(len);
      ++t;
    }
    if (n > tokens_.size() - t)
      return RowError(element, row_index, absl::StrCat("too few values for ", p.name));
    for (uint64_t k = 0; k < n; ++k, ++t) {
      if (!AsciiValueOk(p.type, tokens_[t]))
        return RowError(element, row_index,
                        absl::StrCat("bad value '", Excerpt(tokens_[t]), "' for ", p.name));
      row->values.push_back({tokens_[t], nullptr});
    }
  }
  row->first.push_back(static_cast<uint32_t>(row->values.size()));
  if (t != tokens_.size())
    return RowError(element, row_index,
                    absl::StrCat(tokens_.size() - t, " values more than its properties hold"));
  return absl::OkStatus();
}

absl::Status PlyRowReader::NextBinary(const PlyElement& element, uint64_t row_index, PlyRow* row) {
  for (const PlyProperty& p : element.properties) {
    row->first.push_back(static_cast<uint32_t>(row->values.size()));
    uint64_t n = 1;
    if (p.is_list) {
      const uint8_t* c = nullptr;
      if (!TakeBytes(PlyTypeSize(p.count_type), &c).ok())
        return RowError(element, row_index, "truncated data section");
      const int64_t len = static_cast<int64_t>(PlyBinaryDouble(header_.format, p.count_type, c));
      if (len < 0)
        return RowError(element, row_index, absl::StrCat("negative list length for ", p.name));
      n = static_cast<uint64_t>(len);
    }
    const uint64_t size = PlyTypeSize(p.type);
    if (n > RemainingBytes() / size) return RowError(element, row_index, "truncated data section");
    for (uint64_t k = 0; k < n; ++k) {
      row->values.push_back({{}, reinterpret_cast<const uint8_t*>(bytes_.data()) + pos_});
      pos_ += size;
    }
  }
  row->first.push_back(static_cast<uint32_t>(row->values.size()));
  return absl::OkStatus();
}

absl::Status PlyRowReader::TakeBytes(uint64_t n, const uint8_t** p) {
  if (n > RemainingBytes()) return BadFile(name_, "truncated data section");
  *p = reinterpret_cast<const uint8_t*>(bytes_.data()) + pos_;
  pos_ += n;
  return absl::OkStatus();
}

absl::Status PlyRowReader::Skip(const PlyElement& element) {
  const std::optional<uint64_t> fixed = element.FixedRowBytes();
  if (header_.format != PlyFormat::kAscii && fixed) {
    uint64_t total = 0;
    const uint8_t* p = nullptr;
    if (!CheckedMul(*fixed, element.count, &total) || !TakeBytes(total, &p).ok())
      return BadFile(name_, absl::StrCat("truncated: element ", Excerpt(element.name), " needs ",
                                         element.count, " rows of ", *fixed, " bytes"));
    return absl::OkStatus();
  }
  PlyRow row;
  for (uint64_t r = 0; r < element.count; ++r) RETURN_IF_ERROR(Next(element, r, &row));
  return absl::OkStatus();
}

bool PlyIntValue(PlyFormat format, PlyType type, const PlyValue& v, int64_t* out) {
  if (!PlyTypeIsInteger(type)) return false;
  if (format == PlyFormat::kAscii) return ParseInt(v.text, out) && InRange(type, *out);
  *out = static_cast<int64_t>(PlyBinaryDouble(format, type, v.raw));
  return true;
}

double PlyBinaryDouble(PlyFormat format, PlyType type, const uint8_t* raw) {
  const bool be = format == PlyFormat::kBinaryBigEndian;
  switch (type) {
    case PlyType::kInt8:
      return Load<int8_t>(raw, be);
    case PlyType::kUint8:
      return Load<uint8_t>(raw, be);
    case PlyType::kInt16:
      return Load<int16_t>(raw, be);
    case PlyType::kUint16:
      return Load<uint16_t>(raw, be);
    case PlyType::kInt32:
      return Load<int32_t>(raw, be);
    case PlyType::kUint32:
      return Load<uint32_t>(raw, be);
    case PlyType::kFloat32:
      return Load<float>(raw, be);
    case PlyType::kFloat64:
      return Load<double>(raw, be);
  }
  return 0;
}

float PlyBinaryFloat32(PlyFormat format, const uint8_t* raw) {
  return Load<float>(raw, format == PlyFormat::kBinaryBigEndian);
}

bool TakeFloat32XyzRows(PlyRowReader* reader, const PlyHeader& h, const PlyElement& e,
                        const int prop[3], std::vector<Eigen::Vector3f>* out) {
  const std::optional<uint64_t> row = e.FixedRowBytes();
  if (h.format != PlyFormat::kBinaryLittleEndian || !row || *row == 0 ||
      e.count > reader->RemainingBytes() / *row)
    return false;
  uint64_t offset[3];
  for (int a = 0; a < 3; ++a) {
    if (e.properties[prop[a]].type != PlyType::kFloat32) return false;
    offset[a] = 0;
    for (int i = 0; i < prop[a]; ++i) offset[a] += PlyTypeSize(e.properties[i].type);
  }
  const uint8_t* base = nullptr;
  if (!reader->TakeBytes(*row * e.count, &base).ok()) return false;
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__);
  out->resize(e.count);
  for (uint64_t i = 0; i < e.count; ++i)
    for (int a = 0; a < 3; ++a) std::memcpy(&(*out)[i][a], base + i * *row + offset[a], 4);
  return true;
}

}  // namespace surfinspect
