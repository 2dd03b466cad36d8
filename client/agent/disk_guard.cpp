#include "client/agent/disk_guard.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "core/io/disk_space.h"

namespace surfinspect::client {

absl::StatusOr<DiskConfig> DiskConfigOf(const CellConfig& cell) {
  DiskConfig c;
  const nlohmann::json d = cell.raw.value("disk", nlohmann::json::object());
  if (!d.is_object()) return absl::InvalidArgumentError(cell.path + ": disk: must be an object");
  for (const auto& [key, value] : d.items())
    if (key != "reserve_mb")
      return absl::InvalidArgumentError(
          absl::StrCat(cell.path, ": disk: unknown field \"", key, "\" (known: reserve_mb)"));
  if (d.contains("reserve_mb")) {
    if (!d["reserve_mb"].is_number())
      return absl::InvalidArgumentError(cell.path + ": disk.reserve_mb: a number of MiB expected");
    c.reserve_mb = d["reserve_mb"].get<double>();
  }
  if (!std::isfinite(c.reserve_mb) || c.reserve_mb < 0 || c.reserve_mb > 1e9)
    return absl::InvalidArgumentError(cell.path + ": disk.reserve_mb must be in [0, 1e9] MiB");
  return c;
}

DiskGuard::DiskGuard(std::vector<std::string> folders, const DiskConfig& config)
    : folders_(std::move(folders)),
      reserve_bytes_(static_cast<uint64_t>(config.reserve_mb * (1 << 20))) {}

absl::Status DiskGuard::Check() const {
  const uint64_t need = reserve_bytes_ + need_bytes_;
  for (const std::string& folder : folders_) {
    const absl::StatusOr<DiskSpace> space = DiskSpaceOf(folder);
    if (!space.ok()) continue;  // a folder we cannot ask about fails its own writes
    if (space->free_bytes < need)
      return absl::ResourceExhaustedError(absl::StrCat(
          "disk full: ", folder, " has ", MebibytesText(space->free_bytes), " free; a part needs ",
          MebibytesText(need_bytes_), " plus the reserve of ", MebibytesText(reserve_bytes_)));
  }
  return absl::OkStatus();
}

void DiskGuard::SetWritten(uint64_t bytes) { need_bytes_ = std::max(need_bytes_, bytes); }

void DiskGuard::SetFailed(uint64_t bytes) {
  uint64_t had = bytes;
  if (!folders_.empty())
    if (const absl::StatusOr<DiskSpace> space = DiskSpaceOf(folders_.front()); space.ok())
      had = std::max(had, space->free_bytes);
  need_bytes_ = std::max(need_bytes_, had + kFullDiskSlackBytes);
}

std::vector<FolderSpace> DiskGuard::Space() const {
  std::vector<FolderSpace> out;
  for (const std::string& folder : folders_) {
    const absl::StatusOr<DiskSpace> space = DiskSpaceOf(folder);
    out.push_back({folder, space.ok() ? space->free_bytes : 0});
  }
  return out;
}

std::string DiskMetrics(const std::string& cell, bool full, const std::vector<FolderSpace>& space) {
  std::string out = absl::StrCat(
      "# HELP surfinspect_agent_disk_full 1 while the agent pauses for lack of disk space.\n"
      "# TYPE surfinspect_agent_disk_full gauge\n"
      "surfinspect_agent_disk_full{cell=\"",
      cell, "\"} ", full ? 1 : 0,
      "\n# HELP surfinspect_agent_disk_free_bytes Free space where the agent writes.\n"
      "# TYPE surfinspect_agent_disk_free_bytes gauge\n");
  for (const FolderSpace& f : space)
    absl::StrAppend(&out, "surfinspect_agent_disk_free_bytes{cell=\"", cell, "\",folder=\"",
                    absl::CEscape(f.folder), "\"} ", f.free_bytes, "\n");
  return out;
}

}  // namespace surfinspect::client
