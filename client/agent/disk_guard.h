// Whether the cell-agent has room for the next part's results. A cell PC's
// disk fills slowly and then all at once; a part written half-way helps no
// one. So before each part the agent asks every folder it writes to (the
// results, the archive, the database's) for the reserve cell.json names
// plus the size of the largest part set written so far, and pauses, with
// the parts left in the inbox, until that much is free again.
//
// cell.json:
//   "disk": {"reserve_mb": 512}   free space kept on each folder's file
//                                 system beyond the next part's set, MiB
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "client/cell/cell_config.h"

namespace surfinspect::client {

struct DiskConfig {
  double reserve_mb = 512;  // MiB kept free beyond the next set
};

// cell.json "disk"; InvalidArgument "<cell.json>: disk: ..." for bad values.
absl::StatusOr<DiskConfig> DiskConfigOf(const CellConfig& cell);

struct FolderSpace {
  std::string folder;
  uint64_t free_bytes = 0;
};

class DiskGuard {
 public:
  // `folders`: where the agent writes (a folder not made yet is judged by
  // the nearest one that is).
  DiskGuard(std::vector<std::string> folders, const DiskConfig& config);

  // OK, or ResourceExhausted naming the first folder short of space, what
  // is free there and what is needed.
  absl::Status Check() const;
  // A part's set of `bytes` was written: later parts need as much.
  void SetWritten(uint64_t bytes);
  // A set ran out of space after `bytes` of finished files, its staging
  // folder now removed: it needs more than that and more than is free now
  // in the first folder (what it had, since it took it all), so the agent
  // waits for more room than it failed in instead of failing again.
  void SetFailed(uint64_t bytes);

  uint64_t need_bytes() const { return need_bytes_; }        // the next set, estimated
  uint64_t reserve_bytes() const { return reserve_bytes_; }  // kept free beyond it
  // Each folder's free space now (0 where it cannot be read).
  std::vector<FolderSpace> Space() const;

 private:
  std::vector<std::string> folders_;
  uint64_t reserve_bytes_;
  uint64_t need_bytes_ = 0;
};

// agent_status.prom, beside calibration_status.prom: whether the agent
// pauses for lack of space, and each folder's free bytes (Prometheus text).
std::string DiskMetrics(const std::string& cell, bool full, const std::vector<FolderSpace>& space);

}  // namespace surfinspect::client
