#include "core/io/io_point_cloud.h"

#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>  // PLYWriter only

#include <cstdio>
#include <cstring>
#include <limits>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "core/io/atomic_file.h"
#include "core/io/pcd_format.h"
#include "core/io/ply_cloud.h"
#include "core/io/text_parse.h"

namespace surfinspect {
namespace {

absl::Status Bad(const std::string& path, absl::string_view why) { return BadFile(path, why); }

std::string Extension(const std::string& path) {
  const auto dot = path.rfind('.');
  return dot == std::string::npos ? "" : absl::AsciiStrToLower(path.substr(dot + 1));
}

// ---- writing through PCL ---------------------------------------------

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
  auto bytes = ReadWholeFile(path, std::numeric_limits<uint64_t>::max());
  if (!bytes.ok()) return bytes.status();
  return ext == "pcd" ? ParsePcd(*bytes, limits, path) : ParsePlyCloud(*bytes, limits, path);
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
