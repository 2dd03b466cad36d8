#include "core/io/staged_folder.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include "absl/strings/str_cat.h"

namespace surfinspect {
namespace fs = std::filesystem;
namespace {

constexpr char kStagingFolder[] = ".partial";

// PARENT/NAME with a trailing separator or "." components dropped.
fs::path Normalized(const std::string& target) {
  fs::path p = fs::path(target).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();
  return p;
}

fs::path ParentOf(const fs::path& target) {
  const fs::path parent = target.parent_path();
  return parent.empty() ? fs::path(".") : parent;
}

// A folder's entries on disk: rename(2) is atomic, but only durable once
// the folder holding the new name is synced. EINVAL: nothing to sync.
absl::Status SyncFolder(const fs::path& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return absl::OkStatus();  // reported by the rename that needs it
  const bool synced = ::fsync(fd) == 0 || errno == EINVAL;
  const int error = errno;
  ::close(fd);
  if (!synced)
    return absl::DataLossError(
        absl::StrCat("cannot sync ", dir.string(), ": ", std::strerror(error)));
  return absl::OkStatus();
}

absl::Status Rename(const fs::path& from, const fs::path& to) {
  if (std::rename(from.c_str(), to.c_str()) == 0) return absl::OkStatus();
  return absl::InternalError(absl::StrCat("cannot rename ", from.string(), " to ", to.string(),
                                          ": ", std::strerror(errno)));
}

// The staged files into an existing folder, `last` last.
absl::Status MoveEach(const fs::path& staging, const fs::path& target, const std::string& last) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(staging, ec)) names.push_back(e.path().filename());
  if (ec) return absl::InternalError(absl::StrCat(staging.string(), ": ", ec.message()));
  std::sort(names.begin(), names.end(), [&](const std::string& a, const std::string& b) {
    return std::pair(a == last, a) < std::pair(b == last, b);
  });
  for (const std::string& name : names) {
    if (name == last) {
      if (absl::Status st = SyncFolder(target); !st.ok()) return st;
    }
    if (absl::Status st = Rename(staging / name, target / name); !st.ok()) return st;
  }
  fs::remove(staging, ec);
  return SyncFolder(target);
}

// PARENT/.partial goes when it holds nothing, so that a results folder
// lists exactly its sets between parts; while another set is staged there,
// the removal fails and it stays.
void RemoveRootIfEmpty(const fs::path& staging) {
  std::error_code ec;
  fs::remove(staging.parent_path(), ec);
}

}  // namespace

std::string StagingRoot(const std::string& parent) {
  return (fs::path(parent) / kStagingFolder).string();
}

absl::StatusOr<StagedFolder> StagedFolder::Begin(const std::string& target) {
  static std::atomic<unsigned> counter{0};
  const fs::path t = Normalized(target);
  if (t.empty() || t.filename().empty() || t.filename() == "." || t.filename() == "..")
    return absl::InvalidArgumentError(absl::StrCat("\"", target, "\": not a folder name"));
  const fs::path root = StagingRoot(ParentOf(t).string());
  const fs::path staging =
      root / absl::StrCat(t.filename().string(), ".", ::getpid(), ".", counter++);
  std::error_code ec;
  fs::remove_all(staging, ec);  // a leftover of a process that had our pid
  // Twice: another writer may remove the empty root between its creation
  // and the staging folder's.
  for (int attempt = 0; attempt < 2 && !fs::is_directory(staging, ec); ++attempt)
    fs::create_directories(staging, ec);
  if (!fs::is_directory(staging, ec))
    return absl::PermissionDeniedError(
        absl::StrCat("cannot create ", staging.string(), ": ", ec.message()));
  return StagedFolder(t.string(), staging.string());
}

StagedFolder::StagedFolder(std::string target, std::string staging)
    : target_(std::move(target)), staging_(std::move(staging)) {}

StagedFolder::StagedFolder(StagedFolder&& other) noexcept
    : target_(std::move(other.target_)),
      staging_(std::exchange(other.staging_, std::string())),
      committed_(other.committed_) {}

StagedFolder::~StagedFolder() {
  if (staging_.empty()) return;
  std::error_code ec;
  if (!committed_) fs::remove_all(staging_, ec);
  RemoveRootIfEmpty(staging_);
}

uint64_t StagedFolder::Bytes() const {
  uint64_t bytes = 0;
  std::error_code ec;
  for (const auto& e : fs::recursive_directory_iterator(staging_, ec))
    if (e.is_regular_file(ec)) bytes += e.file_size(ec);
  return bytes;
}

absl::Status StagedFolder::Commit(const std::string& last_file) {
  const fs::path target(target_), staging(staging_);
  if (absl::Status st = SyncFolder(staging); !st.ok()) return st;
  std::error_code ec;
  const bool holds_files = fs::is_directory(target, ec) && !fs::is_empty(target, ec);
  if (!holds_files && fs::exists(target, ec) && !fs::is_directory(target, ec))
    return absl::FailedPreconditionError(absl::StrCat(target_, " exists and is not a folder"));
  absl::Status st = holds_files ? MoveEach(staging, target, last_file) : Rename(staging, target);
  if (st.ok()) st = SyncFolder(ParentOf(target));
  committed_ = st.ok();
  return st;
}

absl::StatusOr<std::vector<std::string>> RemoveStagingLeftovers(const std::string& parent) {
  std::vector<std::string> removed;
  const fs::path root = StagingRoot(parent);
  std::error_code ec;
  if (!fs::exists(root, ec)) return removed;
  for (const auto& e : fs::directory_iterator(root, ec)) removed.push_back(e.path().filename());
  if (ec) return absl::PermissionDeniedError(absl::StrCat(root.string(), ": ", ec.message()));
  std::sort(removed.begin(), removed.end());
  for (const std::string& name : removed) {
    fs::remove_all(root / name, ec);
    if (ec)
      return absl::PermissionDeniedError(
          absl::StrCat("cannot remove ", (root / name).string(), ": ", ec.message()));
  }
  return removed;
}

}  // namespace surfinspect
