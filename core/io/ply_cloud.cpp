#include "core/io/ply_cloud.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <limits>

#include "absl/strings/str_cat.h"
#include "core/io/ply_format.h"
#include "core/io/ply_rows.h"
#include "core/io/text_parse.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

struct VertexLayout {
  int prop[3];         // property index of x, y, z
  PlyType type[3];     // float32 or float64
  uint64_t offset[3];  // byte offset in a fixed-size binary row
};

absl::StatusOr<VertexLayout> FindXyz(const PlyElement& v, std::string_view name) {
  VertexLayout l{};
  for (int a = 0; a < 3; ++a) {
    const char* axis[] = {"x", "y", "z"};
    l.prop[a] = v.FindProperty(axis[a]);
    if (l.prop[a] < 0)
      return BadFile(name, absl::StrCat("PLY vertex element has no '", axis[a], "' property"));
    const PlyProperty& p = v.properties[l.prop[a]];
    if (p.is_list || (p.type != PlyType::kFloat32 && p.type != PlyType::kFloat64))
      return BadFile(name, absl::StrCat("field ", axis[a], " must be float32 or float64"));
    l.type[a] = p.type;
    uint64_t off = 0;
    for (int i = 0; i < l.prop[a]; ++i) off += PlyTypeSize(v.properties[i].type);
    l.offset[a] = off;
  }
  return l;
}

// Each row needs at least its scalars and list length prefixes.
absl::Status CheckBinarySize(std::string_view bytes, const PlyHeader& h, std::string_view name) {
  if (h.format == PlyFormat::kAscii) return absl::OkStatus();
  uint64_t min_bytes = 0;
  for (const PlyElement& e : h.elements) {
    uint64_t row = 0, total = 0;
    for (const PlyProperty& p : e.properties) row += PlyTypeSize(p.is_list ? p.count_type : p.type);
    if (!CheckedMul(row, e.count, &total) || !CheckedAdd(min_bytes, total, &min_bytes))
      return BadFile(name, "PLY header: the declared data size overflows");
  }
  const uint64_t have = bytes.size() - h.data_offset;
  if (have < min_bytes)
    return BadFile(name, absl::StrCat("truncated: declared elements need at least ", min_bytes,
                                      " data bytes, file has ", have));
  return absl::OkStatus();
}

bool AsciiCoordinate(std::string_view tok, PlyType t, float* out) {
  if (t == PlyType::kFloat32) return ParseFloat(tok, out);
  double d;
  if (!ParseDouble(tok, &d)) return false;
  *out = static_cast<float>(d);
  return true;
}

float BinaryCoordinate(PlyFormat f, PlyType t, const uint8_t* raw) {
  return t == PlyType::kFloat32 ? PlyBinaryFloat32(f, raw)
                                : static_cast<float>(PlyBinaryDouble(f, t, raw));
}

absl::Status ReadVertices(PlyRowReader* reader, const PlyHeader& h, const PlyElement& v,
                          const VertexLayout& l, std::string_view name,
                          std::vector<Eigen::Vector3f>* pts) {
  const std::optional<uint64_t> fixed = v.FixedRowBytes();
  if (TakeFloat32XyzRows(reader, h, v, l.prop, pts)) return absl::OkStatus();
  if (h.format != PlyFormat::kAscii && fixed) {
    const uint8_t* base = nullptr;
    if (!reader->TakeBytes(*fixed * v.count, &base).ok())  // fits: CheckBinarySize passed
      return BadFile(name, "truncated data section");
    pts->resize(v.count);
    for (uint64_t i = 0; i < v.count; ++i)
      for (int a = 0; a < 3; ++a)
        (*pts)[i][a] = BinaryCoordinate(h.format, l.type[a], base + i * *fixed + l.offset[a]);
    return absl::OkStatus();
  }
  pts->reserve(std::min<uint64_t>(v.count, reader->RemainingBytes() / 2 + 1));
  PlyRow row;
  for (uint64_t i = 0; i < v.count; ++i) {
    RETURN_IF_ERROR(reader->Next(v, i, &row));
    Eigen::Vector3f p;
    for (int a = 0; a < 3; ++a) {
      const PlyValue& val = row.values[row.first[l.prop[a]]];
      if (h.format != PlyFormat::kAscii) {
        p[a] = BinaryCoordinate(h.format, l.type[a], val.raw);
      } else if (!AsciiCoordinate(val.text, l.type[a], &p[a])) {
        return BadFile(name, absl::StrCat("vertex ", i, ": bad number '", Excerpt(val.text), "'"));
      }
    }
    pts->push_back(p);
  }
  return absl::OkStatus();
}

// range_grid rows: an empty list is an empty cell, else the first index.
absl::Status ReadRangeGrid(PlyRowReader* reader, const PlyHeader& h, const PlyElement& g,
                           uint64_t vertices, std::string_view name, std::vector<int64_t>* cells) {
  int prop = g.FindProperty("vertex_indices");
  if (prop < 0) prop = g.FindProperty("vertex_index");
  if (prop < 0 || !g.properties[prop].is_list || !PlyTypeIsInteger(g.properties[prop].type))
    return BadFile(name, "PLY range_grid has no vertex_indices list");
  cells->reserve(std::min<uint64_t>(g.count, reader->RemainingBytes() + 1));
  PlyRow row;
  for (uint64_t r = 0; r < g.count; ++r) {
    RETURN_IF_ERROR(reader->Next(g, r, &row));
    int64_t idx = -1;
    if (row.first[prop + 1] > row.first[prop] &&
        (!PlyIntValue(h.format, g.properties[prop].type, row.values[row.first[prop]], &idx) ||
         idx < 0 || static_cast<uint64_t>(idx) >= vertices))
      return BadFile(name, absl::StrCat("range_grid ", r, ": vertex index out of range"));
    cells->push_back(idx);
  }
  return absl::OkStatus();
}

absl::Status CheckGrid(const PlyHeader& h, uint64_t vertices, std::string_view name) {
  const int rg = h.FindElement("range_grid");
  // PCL remaps only through a non-empty range_grid of another size.
  const bool remap = rg >= 0 && h.elements[rg].count > 0 && h.elements[rg].count != vertices;
  const uint64_t expected = remap ? h.elements[rg].count : vertices;
  if (!h.num_cols || !h.num_rows) {
    if (remap) return BadFile(name, "PLY range_grid without obj_info num_cols and num_rows");
    return absl::OkStatus();
  }
  uint64_t cells = 0;
  if (!CheckedMul(*h.num_cols, *h.num_rows, &cells) || cells != expected)
    return BadFile(name, absl::StrCat("PLY obj_info grid ", *h.num_cols, " x ", *h.num_rows,
                                      " does not match the ", expected,
                                      remap ? " range_grid cells" : " vertices"));
  return absl::OkStatus();
}

// The cloud of `pts`, in grid order: num_cols x num_rows when the header
// gives both (CheckGrid matched them to the points), unorganized otherwise.
// Cell r is row r / num_cols, column r % num_cols, as in PCL's PLYReader,
// which copies range_grid cell r to point r of its row-major cloud.
absl::StatusOr<PointCloud> Arrange(const PlyHeader& h, std::vector<Eigen::Vector3f> pts,
                                   std::string_view name) {
  PointCloud cloud = PointCloud::Unorganized(std::move(pts));
  if (h.num_cols && h.num_rows) {
    // Each is at most the point count; a truncated one fails Validate.
    cloud.width = static_cast<uint32_t>(*h.num_cols);
    cloud.height = static_cast<uint32_t>(*h.num_rows);
  }
  if (auto st = cloud.Validate(); !st.ok()) return BadFile(name, st.message());
  return cloud;
}

}  // namespace

absl::StatusOr<PointCloud> ParsePlyCloud(std::string_view bytes, const CloudReadLimits& limits,
                                         std::string_view name) {
  ASSIGN_OR_RETURN(auto h, ParsePlyHeader(bytes, limits.max_points, name));
  const int vi = h.FindElement("vertex");
  if (vi < 0 || h.elements[vi].count == 0) return BadFile(name, "PLY has no vertices");
  const PlyElement& vertex = h.elements[vi];
  ASSIGN_OR_RETURN(auto layout, FindXyz(vertex, name));
  RETURN_IF_ERROR(CheckBinarySize(bytes, h, name));
  RETURN_IF_ERROR(CheckGrid(h, vertex.count, name));
  PlyRowReader reader(bytes, h, name);
  std::vector<Eigen::Vector3f> pts;
  std::vector<int64_t> cells;
  for (const PlyElement& e : h.elements) {
    absl::Status st = &e == &vertex ? ReadVertices(&reader, h, e, layout, name, &pts)
                      : e.name == "range_grid"
                          ? ReadRangeGrid(&reader, h, e, vertex.count, name, &cells)
                          : reader.Skip(e);
    if (!st.ok()) return st;
  }
  if (!cells.empty() && cells.size() != pts.size()) {
    std::vector<Eigen::Vector3f> grid(
        cells.size(), Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN()));
    for (std::size_t r = 0; r < cells.size(); ++r)
      if (cells[r] >= 0) grid[r] = pts[cells[r]];
    pts.swap(grid);
  }
  return Arrange(h, std::move(pts), name);
}

namespace {

// A header longer than this is read the general way.
constexpr std::size_t kHeadBytes = 64 * 1024;

struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

// Exactly n bytes at `offset`, or false.
bool ReadAt(int fd, void* out, uint64_t n, uint64_t offset) {
  auto* p = static_cast<char*>(out);
  while (n > 0) {
    const ssize_t got = ::pread(fd, p, n, static_cast<off_t>(offset));
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) return false;
    p += got, n -= static_cast<uint64_t>(got), offset += static_cast<uint64_t>(got);
  }
  return true;
}

// Binary little-endian rows of float32 x, y, z alone (FindXyz at offsets
// 0, 4, 8 of a 12-byte row), in the first element, `vertex`; any other
// element empty (our writer's and PCL's `face 0`); and a grid CheckGrid
// accepts.
bool PackedXyz(const PlyHeader& h, std::string_view name) {
  if (h.format != PlyFormat::kBinaryLittleEndian || h.elements.empty()) return false;
  const PlyElement& v = h.elements[0];
  if (v.name != "vertex" || v.count == 0 || v.FixedRowBytes() != uint64_t{12}) return false;
  const absl::StatusOr<VertexLayout> layout = FindXyz(v, name);
  if (!layout.ok()) return false;
  for (int a = 0; a < 3; ++a)
    if (layout->type[a] != PlyType::kFloat32 || layout->offset[a] != uint64_t{4} * a) return false;
  for (std::size_t e = 1; e < h.elements.size(); ++e)
    if (h.elements[e].count != 0) return false;
  return CheckGrid(h, v.count, name).ok();
}

}  // namespace

std::optional<absl::StatusOr<PointCloud>> ReadPackedXyzPly(const std::string& path,
                                                           const CloudReadLimits& limits) {
  static_assert(sizeof(Eigen::Vector3f) == 12, "points are three packed floats");
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__);
  const Fd file{::open(path.c_str(), O_RDONLY | O_CLOEXEC)};
  struct stat st;
  if (file.fd < 0 || ::fstat(file.fd, &st) != 0 || !S_ISREG(st.st_mode) || st.st_size <= 0)
    return std::nullopt;
  const auto size = static_cast<uint64_t>(st.st_size);
  std::string head(std::min<uint64_t>(size, kHeadBytes), '\0');
  if (!ReadAt(file.fd, head.data(), head.size(), 0)) return std::nullopt;
  const absl::StatusOr<PlyHeader> h = ParsePlyHeader(head, limits.max_points, path);
  // A header must end inside what was read, with its newline: a last line
  // cut at the end of `head` reads as "end_header" there and not in the file.
  if (!h.ok() || !PackedXyz(*h, path) || (head.size() < size && h->data_offset >= head.size()))
    return std::nullopt;
  // The rows must all be there, as CheckBinarySize requires; bytes after
  // them are allowed, as there.
  const uint64_t count = h->elements[0].count;
  if (h->data_offset > size || (size - h->data_offset) / 12 < count) return std::nullopt;
  std::vector<Eigen::Vector3f> pts(count);  // Eigen's points: allocated, not zeroed
  if (!ReadAt(file.fd, pts.data(), 12 * count, h->data_offset)) return std::nullopt;
  return Arrange(*h, std::move(pts), path);
}

}  // namespace surfinspect
