// The agent's housekeeping between parts: result sets a kill left half
// written, the disk guard (disk_guard.h) with its log lines and metrics
// file, and the retention rule (retention.h) applied after each part.
#pragma once

#include <memory>
#include <string>

#include "absl/status/status.h"
#include "client/agent/agent.h"
#include "client/agent/agent_command.h"
#include "client/agent/disk_guard.h"
#include "client/agent/retention.h"

namespace surfinspect::client {

struct Housekeeping {
  std::unique_ptr<DiskGuard> disk;
  RetentionConfig retention;
  std::string status_dir, cell;
  int unsettled = 0;  // parts due for pruning that wait for the store or the broker
};

// Clears interrupted sets, and reads the disk and retention settings.
absl::Status StartHousekeeping(const AgentArgs& a, const CellConfig& cell,
                               const InboxLayout& layout, const std::string& status_dir,
                               const AgentOutput& out, Housekeeping& h);

// The disk guard's listeners: one log line per change, the metrics file.
void WatchDisk(Housekeeping& h, const AgentOutput& out, AgentHooks& hooks);

// Applies the retention rule after a part, telling what it pruned, and how
// many parts wait to be recorded or delivered when that number changes.
void PruneAfterPart(Housekeeping& h, const InboxLayout& layout, const SettledFn& settled,
                    const AgentOutput& out);

}  // namespace surfinspect::client
