// The cell-agent's decisions, as a library: where the inbox, results,
// archive and quarantine are; what to do with one complete part (send it,
// retry, quarantine it, archive it without a call when its results are
// already on disk); and the polling loop over the inbox. The Inspect call and
// the sleep are injected, so the decisions are unit-tested without a server
// or a clock. Nothing here prints or exits: each part ends in a PartReport
// that the caller logs.
//
// Guarantees: a part leaves the inbox only after its results are on disk; a
// part with results is never sent again; a part once judged for quarantine
// is never sent again by this process, even when the move to the quarantine
// fails (it is retried at the next poll); a pass that makes no progress is
// followed by a poll wait, so the loop never spins.
#pragma once

#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "client/agent/disk_guard.h"
#include "client/agent/inbox.h"
#include "client/agent/retry.h"
#include "client/cell/cell_config.h"
#include "client/remote/remote_client.h"

namespace surfinspect::client {

// Folders as given on the command line; empty = default.
struct AgentPaths {
  std::string cell_dir;    // when set: CELL_DIR/{inbox,results,archive,quarantine}
  std::string inbox;       // default "inbox" (relative to the working directory)
  std::string results;     // default "results"
  std::string archive;     // default beside the inbox: <inbox>/../archive
  std::string quarantine;  // default beside the inbox: <inbox>/../quarantine
};

// The layout the paths name: explicit folders win over --cell-dir, which
// wins over the defaults.
InboxLayout ResolveLayout(const AgentPaths& paths);
// Creates the inbox and results folders; names the folder and the error.
absl::Status PrepareDirectories(const InboxLayout& layout);

struct AgentSettings {
  BackoffSettings backoff;  // Inspect retries on UNAVAILABLE, RESOURCE_EXHAUSTED, ...
  double poll_s = 1.0;      // wait after a pass over the inbox that made no progress, s
  bool once = false;        // Run returns when a pass makes no progress or the inbox is empty
};

enum class PartOutcome {
  kDone,                 // sent, results written, scans archived
  kArchivedWithoutCall,  // results were already on disk; scans archived, nothing sent
  kQuarantined,          // can never succeed; moved to the quarantine with error.txt
  kRetryLater,           // left in the inbox (retries exhausted, disk trouble); see message
  kStopped,              // stop requested; left in the inbox
  kConfigError,          // the cell cannot inspect it (uncalibrated viewpoint); stop the agent
};
const char* PartOutcomeName(PartOutcome outcome);

struct PartReport {
  std::string part_id;
  PartOutcome outcome = PartOutcome::kRetryLater;
  std::string message;            // the quarantine reason, or why the part was left / not archived
  std::string verdict;            // kDone: "pass" or "fail"
  double min_mm = 0, max_mm = 0;  // kDone: extremes of the signed deviation, mm
  double seconds = 0;             // wall time spent on the part
  int inspect_calls = 0;
};

struct RunSummary {
  int done = 0, pass = 0, archived_without_call = 0, quarantined = 0;
  bool config_error = false;  // Run stopped on a kConfigError part
  std::string halted;         // Run stopped because before_part refused: its reason
};

// Streams one part (header + views) and returns the server's result.
using InspectFn = std::function<absl::StatusOr<v1::InspectResult>(const v1::PartHeader&,
                                                                  const std::vector<ViewScan>&)>;

struct AgentHooks {
  InspectFn inspect;
  SleepFn sleep = SleepUnlessStopped;  // backoff and poll waits
  // Called before each backoff wait with the part id, the failure, calls so far, the wait (s).
  std::function<void(const std::string&, const absl::Status&, int, double)> on_retry;
  // Listeners (the results store, plant events) are told when a part's scans
  // have been read and it is about to be sent, and when its results are on
  // disk in RESULTS/<id>/, after an inspection or when a restart finds them
  // there. They cannot fail a part: the files are the primary record, so a
  // listener that cannot do its work catches up from them later.
  std::vector<std::function<void(const std::string& part_id)>> on_started;
  std::vector<std::function<void(const std::string& part_id, const std::string& results_dir)>>
      on_stored;
  // Asked before each part is picked up, with the number inspected so far in
  // this Run (e.g. the calibration drift check, client/agent/verify_cell.h).
  // A non-OK answer stops Run: that part and the rest stay in the inbox, and
  // RunSummary::halted carries the message.
  std::function<absl::Status(int parts_done)> before_part;
  // Asked before each part whether its results have room; null = always.
  // While they have none, Run takes no part (they stay in the inbox).
  DiskGuard* disk = nullptr;
  // Told once per change: the reason when the agent pauses for lack of
  // space, "" when it resumes.
  std::vector<std::function<void(const std::string& reason)>> on_disk;
};

class CellAgent {
 public:
  CellAgent(const CellConfig& cell, InboxLayout layout, AgentSettings settings, AgentHooks hooks,
            uint64_t seed);

  // One complete part, start to end.
  PartReport ProcessPart(const std::string& part_id, const std::atomic<bool>& stop);
  // Polls the inbox until `stop` (or, with settings.once, until done);
  // `on_part` sees every part's report as it ends.
  RunSummary Run(const std::atomic<bool>& stop,
                 const std::function<void(const PartReport&)>& on_part);

  const InboxLayout& layout() const { return layout_; }

 private:
  PartReport Steps(const std::string& id, const std::atomic<bool>& stop);
  // `why` by value: it may be an entry of quarantine_pending_, which this erases.
  PartReport QuarantinePart(const std::string& id, std::string why);
  PartReport ArchiveWithoutCall(const std::string& id);
  // Reads INBOX/<id>/<viewpoint>.pcd; a report when the part ends here.
  bool ReadViews(const std::string& id, std::vector<ViewScan>* views, PartReport* report);
  PartReport InspectAndStore(const std::string& id, const std::vector<ViewScan>& views,
                             const std::atomic<bool>& stop);
  void TellStored(const std::string& id) const;
  // Whether the next part's results have room; tells a change of state.
  bool HasRoom();
  void SetDiskFull(const std::string& reason);  // "" = room again
  // The part's CAD mesh for the reports' overlay, read once on first use;
  // null when it cannot be read (the reports then go without the overlay).
  std::shared_ptr<const TriangleMesh> PartMesh();

  const CellConfig& cell_;
  InboxLayout layout_;
  AgentSettings settings_;
  AgentHooks hooks_;
  std::mt19937_64 rng_;
  // Parts judged for quarantine whose move failed: id -> reason.
  std::map<std::string, std::string> quarantine_pending_;
  std::shared_ptr<const TriangleMesh> part_mesh_;
  bool part_mesh_read_ = false;
  std::string disk_full_;  // why the agent pauses; "" = it does not
};

}  // namespace surfinspect::client
