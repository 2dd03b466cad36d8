#include "core/io/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "core/io/disk_space.h"

namespace surfinspect {
namespace {

std::string TempPathFor(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  // Same directory (rename is only atomic within one filesystem); the
  // extension is kept so format-sniffing writers still see it.
  const auto dot = path.rfind('.');
  const auto slash = path.rfind('/');
  const bool has_ext = dot != std::string::npos && (slash == std::string::npos || dot > slash);
  const std::string stem = has_ext ? path.substr(0, dot) : path;
  const std::string ext = has_ext ? path.substr(dot) : "";
  return absl::StrCat(stem, ".tmp-", ::getpid(), "-", counter++, ext);
}

// The temporary file's data and size on disk before the rename, so that a
// crash never leaves the target name on a file without its content.
// EINVAL: the filesystem cannot sync (nothing to wait for).
absl::Status SyncFile(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return absl::OkStatus();  // the writer made it: reported by the rename if gone
  const bool synced = ::fsync(fd) == 0 || errno == EINVAL;
  const int error = errno;
  ::close(fd);
  if (!synced)
    return absl::DataLossError(absl::StrCat("cannot sync ", path, ": ", std::strerror(error)));
  return absl::OkStatus();
}

}  // namespace

absl::Status WriteFileAtomically(
    const std::string& path,
    const std::function<absl::Status(const std::string& tmp_path)>& write_to) {
  const std::string tmp = TempPathFor(path);
  absl::Status st = write_to(tmp);
  if (st.ok()) st = SyncFile(tmp);
  if (st.ok() && std::rename(tmp.c_str(), path.c_str()) != 0)
    st = absl::InternalError(
        absl::StrCat("cannot rename ", tmp, " to ", path, ": ", std::strerror(errno)));
  // Told while the temporary file still holds the space it took: after
  // its removal a full disk no longer looks full.
  if (!st.ok()) st = AsDiskFull(st, tmp);
  if (!st.ok()) std::remove(tmp.c_str());
  return st;
}

absl::Status WriteStringAtomically(const std::string& path, const std::string& bytes) {
  return WriteFileAtomically(path, [&](const std::string& tmp) -> absl::Status {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return absl::PermissionDeniedError(absl::StrCat("cannot create ", tmp));
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) return absl::DataLossError(absl::StrCat("short write to ", tmp));
    return absl::OkStatus();
  });
}

absl::StatusOr<std::string> ReadFileToString(const std::string& path, std::size_t max_bytes) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::NotFoundError(absl::StrCat(path, ": cannot open"));
  in.seekg(0, std::ios::end);
  const auto size = in.tellg();
  if (size < 0) return absl::InvalidArgumentError(absl::StrCat(path, ": not a regular file"));
  if (static_cast<std::size_t>(size) > max_bytes)
    return absl::ResourceExhaustedError(absl::StrCat(path, ": ", static_cast<long long>(size),
                                                     " bytes exceeds the limit of ", max_bytes));
  std::string bytes(static_cast<std::size_t>(size), '\0');
  in.seekg(0);
  in.read(bytes.data(), size);
  if (!in) return absl::DataLossError(absl::StrCat(path, ": read failed"));
  return bytes;
}

}  // namespace surfinspect
