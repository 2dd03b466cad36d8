#include "core/io/disk_space.h"

#include <sys/statvfs.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace surfinspect {
namespace fs = std::filesystem;
namespace {

constexpr char kDiskFullWords[] = "no space left on the file system of ";

// The path itself, or its nearest parent that exists (a results folder not
// yet made is on its parent's file system).
fs::path Existing(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::absolute(path, ec).lexically_normal();
  while (!p.empty() && !fs::exists(p, ec) && p != p.root_path()) p = p.parent_path();
  return p.empty() ? fs::path(".") : p;
}

}  // namespace

absl::StatusOr<DiskSpace> DiskSpaceOf(const std::string& path) {
  struct statvfs s {};
  const fs::path p = Existing(path);
  if (::statvfs(p.c_str(), &s) != 0)
    return absl::NotFoundError(absl::StrCat(path, ": ", std::strerror(errno)));
  DiskSpace d;
  // root writes into the blocks the file system keeps back from others.
  const uint64_t blocks = ::geteuid() == 0 ? s.f_bfree : s.f_bavail;
  d.free_bytes = uint64_t(blocks) * s.f_frsize;
  d.total_bytes = uint64_t(s.f_blocks) * s.f_frsize;
  return d;
}

absl::Status AsDiskFull(const absl::Status& failed, const std::string& path) {
  if (failed.ok() || IsDiskFull(failed)) return failed;
  const absl::StatusOr<DiskSpace> space = DiskSpaceOf(path);
  const bool says_enospc = absl::StrContains(failed.message(), std::strerror(ENOSPC));
  if (!says_enospc && !(space.ok() && space->free_bytes < kFullDiskSlackBytes)) return failed;
  return absl::ResourceExhaustedError(absl::StrCat(
      kDiskFullWords, Existing(path).string(), " (",
      space.ok() ? MebibytesText(space->free_bytes) : "?", " free): ", failed.message()));
}

bool IsDiskFull(const absl::Status& status) {
  return absl::IsResourceExhausted(status) && absl::StartsWith(status.message(), kDiskFullWords);
}

std::string MebibytesText(uint64_t bytes) {
  return absl::StrFormat("%.1f MiB", static_cast<double>(bytes) / (1 << 20));
}

}  // namespace surfinspect
