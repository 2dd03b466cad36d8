#include "core/io/ply_format.h"

#include "absl/strings/str_cat.h"
#include "core/io/text_parse.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

constexpr std::size_t kMaxHeaderBytes = 64 * 1024;

bool ParseType(std::string_view s, PlyType* t) {
  static constexpr struct {
    const char* name;
    PlyType type;
  } kTypes[] = {
      {"char", PlyType::kInt8},      {"int8", PlyType::kInt8},       {"uchar", PlyType::kUint8},
      {"uint8", PlyType::kUint8},    {"short", PlyType::kInt16},     {"int16", PlyType::kInt16},
      {"ushort", PlyType::kUint16},  {"uint16", PlyType::kUint16},   {"int", PlyType::kInt32},
      {"int32", PlyType::kInt32},    {"uint", PlyType::kUint32},     {"uint32", PlyType::kUint32},
      {"float", PlyType::kFloat32},  {"float32", PlyType::kFloat32}, {"double", PlyType::kFloat64},
      {"float64", PlyType::kFloat64}};
  for (const auto& k : kTypes)
    if (s == k.name) {
      *t = k.type;
      return true;
    }
  return false;
}

absl::Status ParseProperty(const std::vector<std::string_view>& tok, std::string_view line,
                           std::string_view name, PlyElement* e) {
  PlyProperty p;
  if (tok.size() == 5 && tok[1] == "list") {
    p.is_list = true;
    if (!ParseType(tok[2], &p.count_type) || !ParseType(tok[3], &p.type))
      return BadFile(name, absl::StrCat("PLY header: bad list type in '", Excerpt(line), "'"));
    if (!PlyTypeIsInteger(p.count_type))
      return BadFile(name, absl::StrCat("PLY header: a list length must be an integer type in '",
                                        Excerpt(line), "'"));
  } else if (tok.size() == 3) {
    if (!ParseType(tok[1], &p.type))
      return BadFile(name, absl::StrCat("PLY header: unknown type '", Excerpt(tok[1]), "'"));
  } else {
    return BadFile(name, absl::StrCat("PLY header: bad property line '", Excerpt(line), "'"));
  }
  p.name = std::string(tok.back());
  if (e->FindProperty(p.name) >= 0)
    return BadFile(name, absl::StrCat("PLY header: repeated property '", Excerpt(p.name),
                                      "' in element ", Excerpt(e->name)));
  e->properties.push_back(std::move(p));
  return absl::OkStatus();
}

absl::Status ParseObjInfo(const std::vector<std::string_view>& tok, std::string_view name,
                          PlyHeader* h) {
  if (tok.size() < 2 || (tok[1] != "num_cols" && tok[1] != "num_rows")) return absl::OkStatus();
  std::optional<uint64_t>& slot = tok[1] == "num_cols" ? h->num_cols : h->num_rows;
  uint64_t v = 0;
  if (tok.size() != 3 || !ParseUint(tok[2], &v))
    return BadFile(name, absl::StrCat("PLY header: bad obj_info ",
                                      tok[1] == "num_cols" ? "num_cols" : "num_rows"));
  if (slot) return BadFile(name, "PLY header: repeated obj_info grid size");
  slot = v;
  return absl::OkStatus();
}

absl::Status ParseFormat(const std::vector<std::string_view>& tok, std::string_view name,
                         bool* seen, PlyHeader* h) {
  if (*seen) return BadFile(name, "PLY header: repeated format line");
  *seen = true;
  const std::string_view f = tok.size() >= 2 ? tok[1] : std::string_view();
  if (f == "ascii") {
    h->format = PlyFormat::kAscii;
  } else if (f == "binary_little_endian") {
    h->format = PlyFormat::kBinaryLittleEndian;
  } else if (f == "binary_big_endian") {
    h->format = PlyFormat::kBinaryBigEndian;
  } else {
    return BadFile(name, absl::StrCat("PLY header: unknown format '", Excerpt(f), "'"));
  }
  if (tok.size() != 3 || tok[2] != "1.0")
    return BadFile(name, "PLY header: format version must be 1.0");
  return absl::OkStatus();
}

absl::Status ParseHeaderLine(std::string_view line, uint64_t max_rows, std::string_view name,
                             bool* format_seen, PlyHeader* h) {
  std::vector<std::string_view> tok;
  SplitWhitespace(line, &tok);
  if (tok.empty()) return absl::OkStatus();
  if (tok[0] == "comment") return absl::OkStatus();
  if (tok[0] == "obj_info") return ParseObjInfo(tok, name, h);
  if (tok[0] == "format") return ParseFormat(tok, name, format_seen, h);
  if (tok[0] == "property") {
    if (h->elements.empty()) return BadFile(name, "PLY header: property before any element");
    return ParseProperty(tok, line, name, &h->elements.back());
  }
  if (tok[0] != "element")
    return BadFile(name, absl::StrCat("PLY header: unknown line '", Excerpt(line), "'"));
  PlyElement e;
  if (tok.size() != 3 || !ParseUint(tok[2], &e.count))
    return BadFile(name, absl::StrCat("PLY header: bad element line '", Excerpt(line), "'"));
  e.name = std::string(tok[1]);
  if (h->FindElement(e.name) >= 0)
    return BadFile(name, absl::StrCat("PLY header: repeated element ", Excerpt(e.name)));
  if (e.count > max_rows)
    return absl::ResourceExhaustedError(absl::StrCat(ToAbsl(name), ": element ", Excerpt(e.name),
                                                     " declares ", e.count,
                                                     " rows, over the limit of ", max_rows));
  h->elements.push_back(std::move(e));
  return absl::OkStatus();
}

}  // namespace

int PlyTypeSize(PlyType t) {
  static constexpr int kSizes[] = {1, 1, 2, 2, 4, 4, 4, 8};
  return kSizes[static_cast<int>(t)];
}

bool PlyTypeIsInteger(PlyType t) { return t != PlyType::kFloat32 && t != PlyType::kFloat64; }

int PlyElement::FindProperty(std::string_view property) const {
  for (std::size_t i = 0; i < properties.size(); ++i)
    if (properties[i].name == property) return static_cast<int>(i);
  return -1;
}

std::optional<uint64_t> PlyElement::FixedRowBytes() const {
  uint64_t n = 0;
  for (const PlyProperty& p : properties) {
    if (p.is_list) return std::nullopt;
    n += PlyTypeSize(p.type);
  }
  return n;
}

int PlyHeader::FindElement(std::string_view element) const {
  for (std::size_t i = 0; i < elements.size(); ++i)
    if (elements[i].name == element) return static_cast<int>(i);
  return -1;
}

absl::StatusOr<PlyHeader> ParsePlyHeader(std::string_view bytes, uint64_t max_rows,
                                         std::string_view name) {
  LineScanner lines(bytes);
  std::string_view line;
  if (!lines.Next(&line) || line != "ply") return BadFile(name, "not a PLY file (no 'ply' magic)");
  PlyHeader h;
  bool format_seen = false;
  while (lines.Next(&line)) {
    if (lines.pos() > kMaxHeaderBytes) return BadFile(name, "header too long or missing its end");
    if (line == "end_header") {
      if (!format_seen) return BadFile(name, "PLY header: no format line");
      for (const PlyElement& e : h.elements)
        if (e.properties.empty() && e.count > 0)
          return BadFile(name, absl::StrCat("PLY header: element ", Excerpt(e.name),
                                            " has rows but no properties"));
      h.data_offset = lines.pos();
      return h;
    }
    RETURN_IF_ERROR(ParseHeaderLine(line, max_rows, name, &format_seen, &h));
  }
  return BadFile(name, "truncated header: no 'end_header' line");
}

}  // namespace surfinspect
