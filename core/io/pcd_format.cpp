#include "core/io/pcd_format.h"

#include <fstream>
#include <limits>
#include <map>

#include "absl/strings/str_cat.h"
#include "core/io/pcd_data.h"
#include "core/io/text_parse.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

constexpr std::size_t kMaxHeaderBytes = 64 * 1024;
constexpr uint64_t kMaxFieldCount = 4096;

using Entries = std::map<std::string, std::vector<std::string_view>>;

bool KnownKey(std::string_view key) {
  for (const char* k : {"VERSION", "FIELDS", "SIZE", "TYPE", "COUNT", "WIDTH", "HEIGHT",
                        "VIEWPOINT", "POINTS", "DATA"})
    if (key == k) return true;
  return false;
}

// Collects "KEY values..." lines up to and including DATA; comments (#) and
// blank lines are skipped, anything else must be a known key, once.
absl::Status ReadEntries(std::string_view bytes, std::string_view name, Entries* entries,
                         std::size_t* data_offset) {
  LineScanner lines(bytes);
  std::string_view line;
  std::vector<std::string_view> tok;
  while (lines.Next(&line)) {
    if (lines.pos() > kMaxHeaderBytes) return BadFile(name, "header too long or missing its end");
    if (IsBlank(line) || line[0] == '#') continue;
    SplitWhitespace(line, &tok);
    std::string key(tok[0]);
    if (key == "COLUMNS") key = "FIELDS";  // PCL's older spelling
    if (!KnownKey(key))
      return BadFile(name, absl::StrCat("PCD header line ", lines.line_number(), ": unknown key '",
                                        Excerpt(tok[0]), "'"));
    if (entries->count(key))
      return BadFile(name,
                     absl::StrCat("PCD header line ", lines.line_number(), ": repeated key ", key));
    (*entries)[key].assign(tok.begin() + 1, tok.end());
    if (key == "DATA") {
      *data_offset = lines.pos();
      return absl::OkStatus();
    }
  }
  return BadFile(name, "truncated header: no 'DATA' line");
}

absl::Status CheckSimpleEntries(const Entries& e, std::string_view name, PcdHeader* h) {
  if (auto it = e.find("VERSION"); it != e.end()) {
    double v = 0;
    if (it->second.size() != 1 || !ParseDouble(it->second[0], &v))
      return BadFile(name, "PCD header: bad VERSION");
  }
  if (auto it = e.find("VIEWPOINT"); it != e.end()) {
    PcdViewpoint vp;
    double* const values[] = {&vp.tx, &vp.ty, &vp.tz, &vp.qw, &vp.qx, &vp.qy, &vp.qz};
    bool ok = it->second.size() == 7;
    for (std::size_t i = 0; ok && i < 7; ++i) ok = ParseDouble(it->second[i], values[i]);
    if (!ok) return BadFile(name, "PCD header: VIEWPOINT needs 7 numbers");
    h->viewpoint = vp;
  }
  return absl::OkStatus();
}

absl::Status BuildFields(const Entries& e, std::string_view name, PcdHeader* h) {
  const auto& fields = e.at("FIELDS");
  const auto& sizes = e.at("SIZE");
  const auto& types = e.at("TYPE");
  const auto count_it = e.find("COUNT");
  if (fields.empty()) return BadFile(name, "PCD header: FIELDS is empty");
  if (sizes.size() != fields.size() || types.size() != fields.size() ||
      (count_it != e.end() && count_it->second.size() != fields.size()))
    return BadFile(name, "PCD header: FIELDS, SIZE, TYPE and COUNT disagree in length");
  for (std::size_t i = 0; i < fields.size(); ++i) {
    PcdField f;
    f.name = std::string(fields[i]);
    uint64_t size = 0, count = 1;
    if (!ParseUint(sizes[i], &size) || !(size == 1 || size == 2 || size == 4 || size == 8))
      return BadFile(name, absl::StrCat("PCD header: bad SIZE for field ", Excerpt(f.name)));
    if (types[i].size() != 1 || std::string_view("FIU").find(types[i][0]) == std::string::npos ||
        (types[i][0] == 'F' && size != 4 && size != 8))
      return BadFile(name, absl::StrCat("PCD header: bad TYPE for field ", Excerpt(f.name)));
    if (count_it != e.end() &&
        (!ParseUint(count_it->second[i], &count) || count == 0 || count > kMaxFieldCount))
      return BadFile(name, absl::StrCat("PCD header: bad COUNT for field ", Excerpt(f.name)));
    for (const PcdField& g : h->fields)
      if (g.name == f.name && f.name != "_")
        return BadFile(name, absl::StrCat("PCD header: repeated field ", Excerpt(f.name)));
    f.size = static_cast<uint32_t>(size);
    f.type = types[i][0];
    f.count = static_cast<uint32_t>(count);
    f.offset = h->point_step;
    h->point_step += size * count;  // <= 64 KiB header / 2 fields * 8 * 4096: no overflow
    h->values_per_point += count;
    h->fields.push_back(f);
  }
  return absl::OkStatus();
}

absl::Status CheckXyz(const PcdHeader& h, std::string_view name) {
  for (const char* axis : {"x", "y", "z"}) {
    bool found = false;
    for (const PcdField& f : h.fields) found |= f.name == axis;
    if (!found) return BadFile(name, "PCD has no x, y and z fields");
  }
  for (const PcdField& f : h.fields)
    if ((f.name == "x" || f.name == "y" || f.name == "z") && f.type != 'F')
      return BadFile(name, absl::StrCat("field ", f.name, " must be float32 or float64"));
  return absl::OkStatus();
}

absl::Status ParseDims(const Entries& e, const CloudReadLimits& limits, std::string_view name,
                       PcdHeader* h) {
  uint64_t width = 0, height = 0, points = 0;
  auto one = [&](const char* key, uint64_t* v) {
    const auto& t = e.at(key);
    return t.size() == 1 && ParseUint(t[0], v);
  };
  if (!one("WIDTH", &width) || !one("HEIGHT", &height) || !one("POINTS", &points))
    return BadFile(name, "PCD header: WIDTH, HEIGHT or POINTS is not a number");
  if (width == 0 || height == 0 || points == 0) return BadFile(name, "PCD holds no points");
  uint64_t product = 0;
  if (width > std::numeric_limits<uint32_t>::max() ||
      height > std::numeric_limits<uint32_t>::max() || !CheckedMul(width, height, &product) ||
      product != points)
    return BadFile(name, absl::StrCat("PCD header: WIDTH*HEIGHT (", width, "*", height,
                                      ") does not equal POINTS (", points, ")"));
  if (points > limits.max_points)
    return absl::ResourceExhaustedError(absl::StrCat(
        ToAbsl(name), ": ", points, " points exceed the limit of ", limits.max_points));
  h->width = static_cast<uint32_t>(width);
  h->height = static_cast<uint32_t>(height);
  h->points = points;
  return absl::OkStatus();
}

absl::Status ParseData(const Entries& e, std::string_view name, PcdHeader* h) {
  const auto& t = e.at("DATA");
  const std::string_view d = t.size() == 1 ? t[0] : std::string_view();
  if (d == "ascii") {
    h->data = PcdData::kAscii;
  } else if (d == "binary") {
    h->data = PcdData::kBinary;
  } else if (d == "binary_compressed") {
    h->data = PcdData::kBinaryCompressed;
  } else {
    return BadFile(name, absl::StrCat("PCD header: unknown DATA encoding '", Excerpt(d), "'"));
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<PcdHeader> ParsePcdHeader(std::string_view bytes, const CloudReadLimits& limits,
                                         std::string_view name) {
  Entries e;
  PcdHeader h;
  RETURN_IF_ERROR(ReadEntries(bytes, name, &e, &h.data_offset));
  for (const char* key : {"FIELDS", "SIZE", "TYPE", "WIDTH", "HEIGHT", "POINTS", "DATA"})
    if (!e.count(key)) return BadFile(name, absl::StrCat("PCD header lacks ", key));
  RETURN_IF_ERROR(CheckSimpleEntries(e, name, &h));
  RETURN_IF_ERROR(BuildFields(e, name, &h));
  RETURN_IF_ERROR(CheckXyz(h, name));
  RETURN_IF_ERROR(ParseDims(e, limits, name, &h));
  RETURN_IF_ERROR(ParseData(e, name, &h));
  return h;
}

absl::StatusOr<PcdHeader> ReadPcdHeader(const std::string& path, const CloudReadLimits& limits) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::NotFoundError(absl::StrCat(path, ": cannot open"));
  // One byte past the longest header: a DATA line cut at the end of the
  // read then ends past kMaxHeaderBytes and is refused, never misread.
  std::string head(kMaxHeaderBytes + 1, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  return ParsePcdHeader(head, limits, path);
}

absl::StatusOr<PointCloud> ParsePcd(std::string_view bytes, const CloudReadLimits& limits,
                                    std::string_view name) {
  ASSIGN_OR_RETURN(auto h, ParsePcdHeader(bytes, limits, name));
  auto cloud = DecodePcdData(bytes, h, name);
  if (!cloud.ok()) return cloud;
  if (auto st = cloud->Validate(); !st.ok()) return BadFile(name, st.message());
  return cloud;
}

}  // namespace surfinspect
