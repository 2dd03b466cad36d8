// Free space on the file system that holds a path, and the one rule that
// tells a write that failed for lack of space from any other failure.
#pragma once

#include <cstdint>
#include <string>

#include "absl/status/statusor.h"

namespace surfinspect {

struct DiskSpace {
  uint64_t free_bytes = 0;   // what this process may still write (root: the reserved blocks too)
  uint64_t total_bytes = 0;  // the file system's size
};

// The file system of `path` (or of its nearest existing parent).
absl::StatusOr<DiskSpace> DiskSpaceOf(const std::string& path);

// Below this much free space a failed write is taken as a full disk, whatever
// the writer said: writers report a short write, a cairo or libpng error, or
// errno, and only the free space tells them all apart.
inline constexpr uint64_t kFullDiskSlackBytes = uint64_t{4} << 20;

// `failed` as ResourceExhausted "no space left on the file system of PATH
// (N MiB free): ..." when it is a write error on a full file system (its
// message says ENOSPC, or less than kFullDiskSlackBytes is free at `path`);
// `failed` itself otherwise.
absl::Status AsDiskFull(const absl::Status& failed, const std::string& path);
bool IsDiskFull(const absl::Status& status);

// "12.3 MiB", for messages.
std::string MebibytesText(uint64_t bytes);

}  // namespace surfinspect
