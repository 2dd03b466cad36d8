#include "core/io/io_point_cloud.h"

#include <cstdint>
#include <limits>
#include <new>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "core/io/atomic_file.h"
#include "core/io/cloud_write.h"
#include "core/io/pcd_format.h"
#include "core/io/ply_cloud.h"
#include "core/io/text_parse.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

absl::Status Bad(const std::string& path, absl::string_view why) { return BadFile(path, why); }

std::string Extension(const std::string& path) {
  const auto dot = path.rfind('.');
  return dot == std::string::npos ? "" : absl::AsciiStrToLower(path.substr(dot + 1));
}

}  // namespace

absl::StatusOr<PointCloud> ReadPointCloud(const std::string& path, const CloudReadLimits& limits) {
  const std::string ext = Extension(path);
  if (ext != "pcd" && ext != "ply")
    return Bad(path, "unknown cloud format (expected .pcd or .ply)");
  if (ext == "ply")
    if (auto direct = ReadPackedXyzPly(path, limits)) return *std::move(direct);
  ASSIGN_OR_RETURN(auto bytes, ReadWholeFile(path, std::numeric_limits<uint64_t>::max()));
  return ext == "pcd" ? ParsePcd(bytes, limits, path) : ParsePlyCloud(bytes, limits, path);
}

absl::Status WritePointCloud(const std::string& path, const PointCloud& cloud,
                             PcdEncoding pcd_encoding, bool ply_binary, std::string_view unit) {
  RETURN_IF_ERROR(cloud.Validate());
  const std::string ext = Extension(path);
  if (ext != "pcd" && ext != "ply")
    return Bad(path, "unknown cloud format (expected .pcd or .ply)");
  const bool empty = ext == "ply" ? cloud.CountValid() == 0 : cloud.empty();
  if (empty) return Bad(path, "refusing to write a cloud with no points");
  // binary_compressed records its sizes as uint32.
  if (ext == "pcd" && pcd_encoding == PcdEncoding::kBinaryCompressed &&
      cloud.size() > UINT32_MAX / 12 / 2)
    return absl::InvalidArgumentError(absl::StrCat(
        path, ": ", cloud.size(), " points are more than a binary_compressed PCD can hold"));
  std::string bytes;
  try {
    bytes =
        ext == "pcd" ? EncodePcd(cloud, pcd_encoding, unit) : EncodePly(cloud, ply_binary, unit);
  } catch (const std::bad_alloc&) {
    return absl::ResourceExhaustedError(
        absl::StrCat(path, ": cannot allocate the file's ", cloud.size(), " points"));
  }
  return WriteStringAtomically(path, bytes);
}

}  // namespace surfinspect
