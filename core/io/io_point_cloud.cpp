#include "core/io/io_point_cloud.h"

#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "core/io/atomic_file.h"

namespace surfinspect {
namespace {

constexpr std::size_t kMaxHeaderBytes = 64 * 1024;

absl::Status Bad(const std::string& path, absl::string_view why) {
  return absl::InvalidArgumentError(absl::StrCat(path, ": ", why));
}

std::string Lower(std::string s) { return absl::AsciiStrToLower(s); }

std::string Extension(const std::string& path) {
  const auto dot = path.rfind('.');
  return dot == std::string::npos ? "" : Lower(path.substr(dot + 1));
}

uint64_t FileSize(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  return in ? static_cast<uint64_t>(in.tellg()) : 0;
}

// Reads header lines up to and including the one starting with `last_key`.
// Returns the lines and the byte offset just after that line.
absl::Status ReadHeaderLines(const std::string& path, absl::string_view last_key,
                             std::vector<std::string>* lines, uint64_t* data_offset) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::NotFoundError(absl::StrCat(path, ": cannot open"));
  std::string line;
  uint64_t offset = 0;
  while (std::getline(in, line)) {
    offset += line.size() + 1;
    if (offset > kMaxHeaderBytes) return Bad(path, "header too long or missing its end");
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines->push_back(line);
    if (absl::StartsWith(line, last_key)) {
      *data_offset = offset;
      return absl::OkStatus();
    }
  }
  return Bad(path, absl::StrCat("truncated header: no '", last_key, "' line"));
}

// Counts non-empty lines after `offset`, stopping once `needed` are seen.
uint64_t CountDataLines(const std::string& path, uint64_t offset, uint64_t needed) {
  std::ifstream in(path, std::ios::binary);
  in.seekg(static_cast<std::streamoff>(offset));
  std::string line;
  uint64_t n = 0;
  while (n < needed && std::getline(in, line))
    if (line.find_first_not_of(" \t\r") != std::string::npos) ++n;
  return n;
}

// ---- PCD header check --------------------------------------------------

absl::Status CheckPcdHeader(const std::string& path, const CloudReadLimits& limits) {
  std::vector<std::string> lines;
  uint64_t data_offset = 0;
  if (auto st = ReadHeaderLines(path, "DATA", &lines, &data_offset); !st.ok()) return st;
  std::map<std::string, std::vector<std::string>> kv;
  for (const auto& l : lines) {
    if (l.empty() || l[0] == '#') continue;
    std::vector<std::string> tok = absl::StrSplit(l, ' ', absl::SkipEmpty());
    if (tok.empty()) continue;
    const std::string key = tok[0];
    tok.erase(tok.begin());
    kv[key] = tok;
  }
  for (const char* key : {"FIELDS", "SIZE", "TYPE", "WIDTH", "HEIGHT", "POINTS", "DATA"})
    if (!kv.count(key)) return Bad(path, absl::StrCat("PCD header lacks ", key));
  const auto& fields = kv["FIELDS"];
  const auto& sizes = kv["SIZE"];
  const auto& types = kv["TYPE"];
  std::vector<std::string> counts =
      kv.count("COUNT") ? kv["COUNT"] : std::vector<std::string>(fields.size(), "1");
  if (sizes.size() != fields.size() || types.size() != fields.size() ||
      counts.size() != fields.size())
    return Bad(path, "PCD header: FIELDS, SIZE, TYPE and COUNT disagree in length");
  uint64_t row_bytes = 0;
  bool has_x = false, has_y = false, has_z = false;
  for (std::size_t i = 0; i < fields.size(); ++i) {
    uint64_t size = 0, count = 0;
    if (!absl::SimpleAtoi(sizes[i], &size) || !(size == 1 || size == 2 || size == 4 || size == 8))
      return Bad(path, absl::StrCat("PCD header: bad SIZE for field ", fields[i]));
    if (!absl::SimpleAtoi(counts[i], &count) || count == 0 || count > 4096)
      return Bad(path, absl::StrCat("PCD header: bad COUNT for field ", fields[i]));
    row_bytes += size * count;
    has_x |= fields[i] == "x";
    has_y |= fields[i] == "y";
    has_z |= fields[i] == "z";
  }
  if (!(has_x && has_y && has_z)) return Bad(path, "PCD has no x, y and z fields");
  uint64_t width = 0, height = 0, points = 0;
  if (!absl::SimpleAtoi(kv["WIDTH"].empty() ? "" : kv["WIDTH"][0], &width) ||
      !absl::SimpleAtoi(kv["HEIGHT"].empty() ? "" : kv["HEIGHT"][0], &height) ||
      !absl::SimpleAtoi(kv["POINTS"].empty() ? "" : kv["POINTS"][0], &points))
    return Bad(path, "PCD header: WIDTH, HEIGHT or POINTS is not a number");
  if (width == 0 || height == 0 || points == 0) return Bad(path, "PCD holds no points");
  if (width > 0xffffffffull || height > 0xffffffffull || width * height != points)
    return Bad(path, absl::StrCat("PCD header: WIDTH*HEIGHT (", width, "*", height,
                                  ") does not equal POINTS (", points, ")"));
  if (points > limits.max_points)
    return absl::ResourceExhaustedError(
        absl::StrCat(path, ": ", points, " points exceed the limit of ", limits.max_points));
  const std::string data = kv["DATA"].empty() ? "" : Lower(kv["DATA"][0]);
  const uint64_t file_size = FileSize(path);
  if (data == "binary") {
    if (file_size < data_offset + points * row_bytes)
      return Bad(path, absl::StrCat("truncated: ", points, " points need ", points * row_bytes,
                                    " data bytes, file has ", file_size - data_offset));
  } else if (data == "binary_compressed") {
    uint32_t sizes_hdr[2] = {0, 0};
    std::ifstream in(path, std::ios::binary);
    in.seekg(static_cast<std::streamoff>(data_offset));
    in.read(reinterpret_cast<char*>(sizes_hdr), sizeof(sizes_hdr));
    if (!in) return Bad(path, "truncated: compressed block sizes missing");
    if (sizes_hdr[1] != points * row_bytes)
      return Bad(path, "compressed PCD: uncompressed size disagrees with the header");
    if (sizes_hdr[0] == 0 || data_offset + 8 + sizes_hdr[0] > file_size)
      return Bad(path, "truncated: compressed data shorter than declared");
  } else if (data == "ascii") {
    const uint64_t lines_found = CountDataLines(path, data_offset, points);
    if (lines_found < points)
      return Bad(path, absl::StrCat("truncated: ", points, " points declared, ", lines_found,
                                    " data lines found"));
  } else {
    return Bad(path, absl::StrCat("PCD header: unknown DATA encoding '", data, "'"));
  }
  return absl::OkStatus();
}

// ---- PLY header check --------------------------------------------------

int PlyTypeSize(const std::string& t) {
  static const std::map<std::string, int> sizes = {
      {"char", 1},   {"int8", 1},    {"uchar", 1},  {"uint8", 1},  {"short", 2}, {"int16", 2},
      {"ushort", 2}, {"uint16", 2},  {"int", 4},    {"int32", 4},  {"uint", 4},  {"uint32", 4},
      {"float", 4},  {"float32", 4}, {"double", 8}, {"float64", 8}};
  auto it = sizes.find(t);
  return it == sizes.end() ? 0 : it->second;
}

absl::Status CheckPlyHeader(const std::string& path, const CloudReadLimits& limits) {
  std::vector<std::string> lines;
  uint64_t data_offset = 0;
  if (auto st = ReadHeaderLines(path, "end_header", &lines, &data_offset); !st.ok()) return st;
  if (lines.empty() || lines[0] != "ply") return Bad(path, "not a PLY file (no 'ply' magic)");
  std::string format;
  struct Element {
    std::string name;
    uint64_t count = 0;
    uint64_t min_row_bytes = 0;
    std::vector<std::string> props;
  };
  std::vector<Element> elements;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    std::vector<std::string> tok = absl::StrSplit(lines[i], ' ', absl::SkipEmpty());
    if (tok.empty()) continue;
    if (tok[0] == "format" && tok.size() >= 2) {
      format = tok[1];
    } else if (tok[0] == "element") {
      Element e;
      if (tok.size() != 3 || !absl::SimpleAtoi(tok[2], &e.count))
        return Bad(path, absl::StrCat("PLY header: bad element line '", lines[i], "'"));
      e.name = tok[1];
      elements.push_back(e);
    } else if (tok[0] == "property") {
      if (elements.empty()) return Bad(path, "PLY header: property before any element");
      Element& e = elements.back();
      if (tok.size() == 5 && tok[1] == "list") {
        const int n = PlyTypeSize(tok[2]);
        if (n == 0 || PlyTypeSize(tok[3]) == 0)
          return Bad(path, absl::StrCat("PLY header: bad list type in '", lines[i], "'"));
        e.min_row_bytes += n;  // at least the length prefix
      } else if (tok.size() == 3) {
        const int n = PlyTypeSize(tok[1]);
        if (n == 0) return Bad(path, absl::StrCat("PLY header: unknown type '", tok[1], "'"));
        e.min_row_bytes += n;
      } else {
        return Bad(path, absl::StrCat("PLY header: bad property line '", lines[i], "'"));
      }
      e.props.push_back(tok.back());
    }
  }
  if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
    return Bad(path, absl::StrCat("PLY header: unknown format '", format, "'"));
  const Element* vertex = nullptr;
  uint64_t min_bytes = 0, total_rows = 0;
  for (const auto& e : elements) {
    if (e.count > limits.max_points)
      return absl::ResourceExhaustedError(absl::StrCat(path, ": element ", e.name, " declares ",
                                                       e.count, " rows, over the limit of ",
                                                       limits.max_points));
    min_bytes += e.count * e.min_row_bytes;
    total_rows += e.count;
    if (e.name == "vertex") vertex = &e;
  }
  if (!vertex || vertex->count == 0) return Bad(path, "PLY has no vertices");
  for (const char* axis : {"x", "y", "z"})
    if (std::find(vertex->props.begin(), vertex->props.end(), axis) == vertex->props.end())
      return Bad(path, absl::StrCat("PLY vertex element has no '", axis, "' property"));
  const uint64_t file_size = FileSize(path);
  if (format == "ascii") {
    const uint64_t lines_found = CountDataLines(path, data_offset, total_rows);
    if (lines_found < total_rows)
      return Bad(
          path, absl::StrCat("truncated: ", total_rows, " rows declared, ", lines_found, " found"));
  } else if (file_size < data_offset + min_bytes) {
    return Bad(path, absl::StrCat("truncated: declared elements need at least ", min_bytes,
                                  " data bytes, file has ", file_size - data_offset));
  }
  return absl::OkStatus();
}

// ---- conversion to and from PCLPointCloud2 -----------------------------

absl::StatusOr<PointCloud> FromBlob(const std::string& path, const pcl::PCLPointCloud2& blob,
                                    bool keep_grid) {
  int offsets[3] = {-1, -1, -1};
  uint8_t types[3] = {0, 0, 0};
  for (const auto& f : blob.fields) {
    const int axis = f.name == "x" ? 0 : f.name == "y" ? 1 : f.name == "z" ? 2 : -1;
    if (axis < 0) continue;
    if (f.datatype != pcl::PCLPointField::FLOAT32 && f.datatype != pcl::PCLPointField::FLOAT64)
      return Bad(path, absl::StrCat("field ", f.name, " must be float32 or float64"));
    offsets[axis] = static_cast<int>(f.offset);
    types[axis] = f.datatype;
  }
  if (offsets[0] < 0 || offsets[1] < 0 || offsets[2] < 0)
    return Bad(path, "cloud has no x, y and z fields");
  const uint64_t n = uint64_t{blob.width} * blob.height;
  const uint64_t needed_row = uint64_t{blob.width} * blob.point_step;
  if (n == 0) return Bad(path, "cloud holds no points");
  if (blob.row_step < needed_row || blob.data.size() < uint64_t{blob.row_step} * blob.height)
    return Bad(path, "cloud data is shorter than its declared size");
  for (int a = 0; a < 3; ++a) {
    const int sz = types[a] == pcl::PCLPointField::FLOAT32 ? 4 : 8;
    if (static_cast<uint64_t>(offsets[a]) + sz > blob.point_step)
      return Bad(path, "field offset outside the point record");
  }
  PointCloud cloud;
  cloud.points.resize(n);
  for (uint32_t r = 0; r < blob.height; ++r)
    for (uint32_t c = 0; c < blob.width; ++c) {
      const uint8_t* rec =
          blob.data.data() + uint64_t{r} * blob.row_step + uint64_t{c} * blob.point_step;
      Eigen::Vector3f& p = cloud.points[uint64_t{r} * blob.width + c];
      for (int a = 0; a < 3; ++a) {
        if (types[a] == pcl::PCLPointField::FLOAT32) {
          std::memcpy(&p[a], rec + offsets[a], 4);
        } else {
          double d;
          std::memcpy(&d, rec + offsets[a], 8);
          p[a] = static_cast<float>(d);
        }
      }
    }
  if (keep_grid) {
    cloud.width = blob.width;
    cloud.height = blob.height;
  } else {
    cloud.width = static_cast<uint32_t>(n);
    cloud.height = 1;
  }
  if (auto st = cloud.Validate(); !st.ok()) return Bad(path, st.message());
  return cloud;
}

pcl::PCLPointCloud2 ToBlob(const PointCloud& cloud, bool valid_only) {
  pcl::PCLPointCloud2 blob;
  for (int a = 0; a < 3; ++a) {
    pcl::PCLPointField f;
    f.name = std::string(1, "xyz"[a]);
    f.offset = 4 * a;
    f.datatype = pcl::PCLPointField::FLOAT32;
    f.count = 1;
    blob.fields.push_back(f);
  }
  blob.point_step = 12;
  std::vector<Eigen::Vector3f> valid;
  const std::vector<Eigen::Vector3f>* pts = &cloud.points;
  if (valid_only) {
    cloud.ForEachValid([&](std::size_t, const Eigen::Vector3f& p) { valid.push_back(p); });
    pts = &valid;
    blob.width = static_cast<uint32_t>(valid.size());
    blob.height = 1;
  } else {
    blob.width = cloud.width;
    blob.height = cloud.height;
  }
  blob.row_step = blob.width * blob.point_step;
  blob.is_dense = valid_only || cloud.CountValid() == cloud.size();
  blob.data.resize(pts->size() * 12);
  if (!pts->empty()) std::memcpy(blob.data.data(), pts->data(), blob.data.size());
  return blob;
}

// PCL 1.13's PLY ASCII writer ignores its precision argument and prints 6
// significant digits, which rounds millimetre coordinates to ~0.1 mm. ASCII
// PLY is therefore written here with 9 significant digits (float round-trip).
absl::Status WritePlyAscii(const std::string& tmp, const PointCloud& cloud) {
  std::FILE* f = std::fopen(tmp.c_str(), "w");
  if (!f) return absl::PermissionDeniedError(absl::StrCat("cannot create ", tmp));
  std::fprintf(f,
               "ply\nformat ascii 1.0\ncomment surfinspect\nelement vertex %zu\n"
               "property float x\nproperty float y\nproperty float z\nend_header\n",
               cloud.CountValid());
  cloud.ForEachValid([&](std::size_t, const Eigen::Vector3f& p) {
    std::fprintf(f, "%.9g %.9g %.9g\n", p.x(), p.y(), p.z());
  });
  const bool ok = std::ferror(f) == 0;
  return std::fclose(f) == 0 && ok ? absl::OkStatus()
                                   : absl::DataLossError(absl::StrCat("short write to ", tmp));
}

}  // namespace

absl::StatusOr<PointCloud> ReadPointCloud(const std::string& path, const CloudReadLimits& limits) {
  const std::string ext = Extension(path);
  if (ext != "pcd" && ext != "ply")
    return Bad(path, "unknown cloud format (expected .pcd or .ply)");
  if (FileSize(path) == 0) {
    std::ifstream probe(path);
    if (!probe) return absl::NotFoundError(absl::StrCat(path, ": cannot open"));
    return Bad(path, "file is empty");
  }
  auto check = ext == "pcd" ? CheckPcdHeader(path, limits) : CheckPlyHeader(path, limits);
  if (!check.ok()) return check;
  pcl::PCLPointCloud2 blob;
  Eigen::Vector4f origin;
  Eigen::Quaternionf orientation;
  int version = 0;
  int rc = -1;
  try {
    if (ext == "pcd") {
      pcl::PCDReader reader;
      rc = reader.read(path, blob, origin, orientation, version);
    } else {
      pcl::PLYReader reader;
      rc = reader.read(path, blob, origin, orientation, version);
    }
  } catch (const std::exception& e) {
    return Bad(path, absl::StrCat("parser error: ", e.what()));
  }
  if (rc < 0) return Bad(path, "PCL could not parse the file (malformed body)");
  return FromBlob(path, blob, /*keep_grid=*/ext == "pcd");
}

absl::Status WritePointCloud(const std::string& path, const PointCloud& cloud,
                             PcdEncoding pcd_encoding, bool ply_binary) {
  if (auto st = cloud.Validate(); !st.ok()) return st;
  const std::string ext = Extension(path);
  if (ext != "pcd" && ext != "ply")
    return Bad(path, "unknown cloud format (expected .pcd or .ply)");
  const pcl::PCLPointCloud2 blob = ToBlob(cloud, /*valid_only=*/ext == "ply");
  if (blob.width == 0) return Bad(path, "refusing to write a cloud with no points");
  return WriteFileAtomically(path, [&](const std::string& tmp) -> absl::Status {
    int rc = -1;
    try {
      if (ext == "pcd") {
        pcl::PCDWriter w;
        switch (pcd_encoding) {
          case PcdEncoding::kAscii:
            rc =
                w.writeASCII(tmp, blob, Eigen::Vector4f::Zero(), Eigen::Quaternionf::Identity(), 9);
            break;
          case PcdEncoding::kBinary:
            rc = w.writeBinary(tmp, blob);
            break;
          case PcdEncoding::kBinaryCompressed:
            rc = w.writeBinaryCompressed(tmp, blob);
            break;
        }
      } else if (ply_binary) {
        pcl::PLYWriter w;
        rc = w.writeBinary(tmp, blob, Eigen::Vector4f::Zero(), Eigen::Quaternionf::Identity(),
                           /*use_camera=*/false);
      } else {
        return WritePlyAscii(tmp, cloud);
      }
    } catch (const std::exception& e) {
      return absl::InternalError(absl::StrCat(path, ": writer error: ", e.what()));
    }
    if (rc < 0) return absl::InternalError(absl::StrCat(path, ": PCL failed to write"));
    return absl::OkStatus();
  });
}

}  // namespace surfinspect
