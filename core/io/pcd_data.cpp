#include "core/io/pcd_data.h"

#include <algorithm>
#include <cstring>
#include <limits>

#include "absl/strings/str_cat.h"
#include "core/io/lzf.h"
#include "core/io/text_parse.h"

namespace surfinspect {
namespace {

struct AxisLayout {
  uint64_t offset[3];     // byte offset in a binary record
  uint32_t size[3];       // 4 or 8
  uint64_t token[3];      // value index on an ascii line
  uint64_t soa_start[3];  // byte offset of the field's block in decoded compressed data
};

AxisLayout Layout(const PcdHeader& h) {
  AxisLayout l{};
  uint64_t token = 0, soa = 0;
  for (const PcdField& f : h.fields) {
    const int a = f.name == "x" ? 0 : f.name == "y" ? 1 : f.name == "z" ? 2 : -1;
    if (a >= 0) {
      l.offset[a] = f.offset;
      l.size[a] = f.size;
      l.token[a] = token;
      l.soa_start[a] = soa;
    }
    token += f.count;
    soa += uint64_t{f.size} * f.count * h.points;  // <= decoded size, checked by the caller
  }
  return l;
}

float ToFloat(const uint8_t* p, uint32_t size) {
  if (size == 4) {
    float f;
    std::memcpy(&f, p, 4);
    return f;
  }
  double d;
  std::memcpy(&d, p, 8);
  return static_cast<float>(d);
}

PointCloud EmptyGrid(const PcdHeader& h) {
  PointCloud c;
  c.width = h.width;
  c.height = h.height;
  c.points.resize(h.points);
  return c;
}

absl::StatusOr<PointCloud> DecodeBinary(std::string_view data, const PcdHeader& h,
                                        std::string_view name) {
  uint64_t need = 0;
  if (!CheckedMul(h.points, h.point_step, &need))
    return BadFile(name, "PCD header: the declared data size overflows");
  if (data.size() < need)
    return BadFile(name, absl::StrCat("truncated: ", h.points, " points need ", need,
                                      " data bytes, file has ", data.size()));
  const AxisLayout l = Layout(h);
  PointCloud c = EmptyGrid(h);
  const auto* base = reinterpret_cast<const uint8_t*>(data.data());
  for (uint64_t i = 0; i < h.points; ++i) {
    const uint8_t* rec = base + i * h.point_step;
    for (int a = 0; a < 3; ++a) c.points[i][a] = ToFloat(rec + l.offset[a], l.size[a]);
  }
  return c;
}

absl::StatusOr<PointCloud> DecodeCompressed(std::string_view data, const PcdHeader& h,
                                            std::string_view name) {
  uint32_t sizes[2];
  if (data.size() < 8) return BadFile(name, "truncated: compressed block sizes missing");
  std::memcpy(sizes, data.data(), 8);
  uint64_t need = 0;
  if (!CheckedMul(h.points, h.point_step, &need) || sizes[1] != need)
    return BadFile(name, "compressed PCD: uncompressed size disagrees with the header");
  if (sizes[0] == 0 || sizes[0] > data.size() - 8)
    return BadFile(name, "truncated: compressed data shorter than declared");
  auto decoded = LzfDecompress(data.substr(8, sizes[0]), sizes[1]);
  if (!decoded.ok())
    return BadFile(name, absl::StrCat("compressed PCD: ", decoded.status().message()));
  // The decoded block is field-major: all x values, then all y values, ...
  const AxisLayout l = Layout(h);
  PointCloud c = EmptyGrid(h);
  for (uint64_t i = 0; i < h.points; ++i)
    for (int a = 0; a < 3; ++a)
      c.points[i][a] = ToFloat(decoded->data() + l.soa_start[a] + i * l.size[a], l.size[a]);
  return c;
}

// PCL's ascii values: "nan" (any case) is a quiet NaN, others decimal.
bool AsciiValue(std::string_view tok, uint32_t size, float* out) {
  if (tok.size() == 3 && (tok[0] | 0x20) == 'n' && (tok[1] | 0x20) == 'a' &&
      (tok[2] | 0x20) == 'n') {
    *out = std::numeric_limits<float>::quiet_NaN();
    return true;
  }
  if (size == 4) return ParseFloat(tok, out);
  double d;
  if (!ParseDouble(tok, &d)) return false;
  *out = static_cast<float>(d);
  return true;
}

absl::StatusOr<PointCloud> DecodeAscii(std::string_view bytes, const PcdHeader& h,
                                       std::string_view name) {
  const AxisLayout l = Layout(h);
  PointCloud c;
  c.width = h.width;
  c.height = h.height;
  // An ascii number takes at least 2 bytes with its separator.
  const uint64_t fit = (bytes.size() - h.data_offset) / 2 / h.values_per_point + 1;
  c.points.reserve(std::min(h.points, fit));
  LineScanner lines(bytes, h.data_offset);
  std::string_view line;
  std::vector<std::string_view> tok;
  while (c.points.size() < h.points && lines.Next(&line)) {
    if (IsBlank(line)) continue;
    SplitWhitespace(line, &tok);
    if (tok.size() != h.values_per_point)
      return BadFile(name, absl::StrCat("data line ", c.points.size() + 1, " has ", tok.size(),
                                        " values, the header declares ", h.values_per_point));
    Eigen::Vector3f p;
    for (int a = 0; a < 3; ++a)
      if (!AsciiValue(tok[l.token[a]], l.size[a], &p[a]))
        return BadFile(name, absl::StrCat("data line ", c.points.size() + 1, ": bad number '",
                                          Excerpt(tok[l.token[a]]), "'"));
    c.points.push_back(p);
  }
  if (c.points.size() < h.points)
    return BadFile(name, absl::StrCat("truncated: ", h.points, " points declared, ",
                                      c.points.size(), " data lines found"));
  return c;
}

}  // namespace

absl::StatusOr<PointCloud> DecodePcdData(std::string_view bytes, const PcdHeader& h,
                                         std::string_view name) {
  const std::string_view data = bytes.substr(h.data_offset);
  switch (h.data) {
    case PcdData::kBinary:
      return DecodeBinary(data, h, name);
    case PcdData::kBinaryCompressed:
      return DecodeCompressed(data, h, name);
    case PcdData::kAscii:
      break;
  }
  return DecodeAscii(bytes, h, name);
}

}  // namespace surfinspect
