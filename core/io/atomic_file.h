// Atomic file output: write everything to a temporary file beside the
// target, flush it, then rename(2) over the target. A reader (or a crash)
// therefore sees either the old file or the complete new one, never half.
#pragma once

#include <functional>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace surfinspect {

// `write_to` receives the temporary path and must create the file there. On
// any failure the temporary file is removed and the target is untouched; a
// failure on a full file system is ResourceExhausted (core/io/disk_space.h).
absl::Status WriteFileAtomically(
    const std::string& path,
    const std::function<absl::Status(const std::string& tmp_path)>& write_to);

// Convenience for in-memory content.
absl::Status WriteStringAtomically(const std::string& path, const std::string& bytes);

// Reads a whole file; NotFound / a clear error naming the path otherwise.
absl::StatusOr<std::string> ReadFileToString(const std::string& path,
                                             std::size_t max_bytes = std::size_t{4} << 30);

}  // namespace surfinspect
