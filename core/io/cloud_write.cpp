#include "core/io/cloud_write.h"

#include <cmath>
#include <cstdio>
#include <cstring>

#include "absl/strings/str_cat.h"
#include "core/io/lzf.h"

namespace surfinspect {
namespace {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "binary clouds are written as the machine's float bytes, little-endian");

constexpr std::size_t kPclPage = 4096;

// The unit as a comment line (PCL and our reader skip '#' lines), or none.
std::string PcdHeader(const PointCloud& cloud, const char* data, std::string_view unit) {
  return absl::StrCat("# .PCD v0.7 - Point Cloud Data file format\n",
                      unit.empty() ? "" : absl::StrCat("# units: ", std::string(unit), "\n"),
                      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\n"
                      "TYPE F F F\nCOUNT 1 1 1\nWIDTH ",
                      cloud.width, "\nHEIGHT ", cloud.height, "\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS ",
                      cloud.size(), "\nDATA ", data, "\n");
}

// One float as PCL's ascii writers print it: a stream of precision 9 (%.9g),
// and "nan" for every NaN whatever its sign bit.
void AppendFloat(float v, std::string& out) {
  if (std::isnan(v)) {
    out += "nan";
    return;
  }
  char buf[32];
  const int len = std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(v));
  out.append(buf, static_cast<std::size_t>(len));
}

void AppendAsciiPoint(const Eigen::Vector3f& p, std::string& out) {
  for (int a = 0; a < 3; ++a) {
    if (a > 0) out += ' ';
    AppendFloat(p[a], out);
  }
  out += '\n';
}

void AppendRaw(const PointCloud& cloud, std::string& out) {
  out.append(reinterpret_cast<const char*>(cloud.points.data()), cloud.size() * 12);
}

void AppendU32(uint32_t v, std::string& out) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

// PCD binary_compressed: the planes x..., y..., z..., then LZF.
void AppendCompressed(const PointCloud& cloud, std::string& out) {
  const std::size_t n = cloud.size();
  std::string planes(n * 12, '\0');
  for (int a = 0; a < 3; ++a)
    for (std::size_t i = 0; i < n; ++i)
      std::memcpy(&planes[(a * n + i) * 4], &cloud.points[i][a], 4);
  const std::string packed = LzfCompress(planes);
  AppendU32(static_cast<uint32_t>(packed.size()), out);
  AppendU32(static_cast<uint32_t>(planes.size()), out);
  out += packed;
}

std::string PlyUnitComment(std::string_view unit) {
  return unit.empty() ? "" : absl::StrCat("comment units: ", std::string(unit), "\n");
}

std::string PlyBinaryHeader(std::size_t count, std::string_view unit) {
  return absl::StrCat(
      "ply\nformat binary_little_endian 1.0\ncomment PCL generated\n", PlyUnitComment(unit),
      "obj_info is_cyberware_data 0\nobj_info is_mesh 0\nobj_info is_warped 0\n"
      "obj_info is_interlaced 0\nobj_info num_cols ",
      count,
      "\nobj_info num_rows 1\nobj_info echo_rgb_offset_x 0\nobj_info echo_rgb_offset_y 0\n"
      "obj_info echo_rgb_offset_z 0\nobj_info echo_rgb_frontfocus 0.0\n"
      "obj_info echo_rgb_backfocus 0.0\nobj_info echo_rgb_pixelsize 0.0\n"
      "obj_info echo_rgb_centerpixel 0\nobj_info echo_frames 1\nobj_info echo_lgincr 0.0\n"
      "element vertex ",
      count,
      "\nproperty float x\nproperty float y\nproperty float z\nelement face 0\nend_header\n");
}

}  // namespace

std::string EncodePcd(const PointCloud& cloud, PcdEncoding encoding, std::string_view unit) {
  switch (encoding) {
    case PcdEncoding::kAscii: {
      std::string out = PcdHeader(cloud, "ascii", unit);
      out.reserve(out.size() + cloud.size() * 40);
      for (const Eigen::Vector3f& p : cloud.points) AppendAsciiPoint(p, out);
      return out;
    }
    case PcdEncoding::kBinary: {
      std::string out = PcdHeader(cloud, "binary", unit);
      const std::size_t padding = (out.size() + kPclPage - 1) / kPclPage * kPclPage - out.size();
      out.reserve(out.size() + cloud.size() * 12 + padding);
      AppendRaw(cloud, out);
      out.append(padding, '\0');
      return out;
    }
    case PcdEncoding::kBinaryCompressed: {
      std::string out = PcdHeader(cloud, "binary_compressed", unit);
      AppendCompressed(cloud, out);
      return out;
    }
  }
  return {};
}

std::string EncodePly(const PointCloud& cloud, bool binary, std::string_view unit) {
  const std::size_t valid = cloud.CountValid();
  std::string out =
      binary ? PlyBinaryHeader(valid, unit)
             : absl::StrCat("ply\nformat ascii 1.0\ncomment surfinspect\n", PlyUnitComment(unit),
                            "element vertex ", valid,
                            "\nproperty float x\nproperty float y\nproperty float z\nend_header\n");
  out.reserve(out.size() + valid * (binary ? 12 : 40));
  cloud.ForEachValid([&](std::size_t, const Eigen::Vector3f& p) {
    if (binary) {
      out.append(reinterpret_cast<const char*>(p.data()), 12);
      return;
    }
    AppendAsciiPoint(p, out);  // valid: never "nan"
  });
  return out;
}

}  // namespace surfinspect
