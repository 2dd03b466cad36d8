#include "client/agent/housekeeping.h"

#include <chrono>
#include <filesystem>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "client/agent/inbox.h"
#include "core/io/atomic_file.h"
#include "core/types/status_macros.h"

namespace surfinspect::client {
namespace {

void Tell(const std::function<void(const std::string&)>& to, const std::string& line) {
  if (to) to(line);
}

void WriteDiskMetrics(const Housekeeping& h, bool full, const AgentOutput& out) {
  const std::string path = h.status_dir + "/agent_status.prom";
  if (absl::Status st = WriteStringAtomically(path, DiskMetrics(h.cell, full, h.disk->Space()));
      !st.ok())
    Tell(out.warn, absl::StrCat("cannot write ", path, ": ", st.message()));
}

}  // namespace

absl::Status StartHousekeeping(const AgentArgs& a, const CellConfig& cell,
                               const InboxLayout& layout, const std::string& status_dir,
                               const AgentOutput& out, Housekeeping& h) {
  ASSIGN_OR_RETURN(const std::vector<std::string> leftovers, RemoveUnfinishedSets(layout.results));
  if (!leftovers.empty())
    Tell(out.warn, absl::StrCat("removed ", leftovers.size(), " unfinished result sets (",
                                absl::StrJoin(leftovers, ", "),
                                "): their parts are in the inbox and are inspected again"));
  ASSIGN_OR_RETURN(const DiskConfig disk, DiskConfigOf(cell));
  ASSIGN_OR_RETURN(h.retention, RetentionConfigOf(cell));
  std::vector<std::string> folders = {layout.results, layout.archive};
  const std::string db = a.db.empty() ? layout.results + "/results.db" : a.db;
  if (a.db != "none" && db.find("://") == std::string::npos)  // a file, not a server's URL
    folders.push_back(std::filesystem::path(db).parent_path().string());
  h.disk = std::make_unique<DiskGuard>(std::move(folders), disk);
  h.status_dir = status_dir;
  h.cell = cell.name;
  WriteDiskMetrics(h, false, out);
  return absl::OkStatus();
}

void WatchDisk(Housekeeping& h, const AgentOutput& out, AgentHooks& hooks) {
  hooks.disk = h.disk.get();
  hooks.on_disk.push_back([&h, &out](const std::string& reason) {
    if (!reason.empty())
      Tell(out.error, absl::StrCat(reason, "; parts wait in the inbox until space returns"));
    else
      Tell(out.info, "disk space is back; taking parts again");
    WriteDiskMetrics(h, !reason.empty(), out);
  });
}

void PruneAfterPart(Housekeeping& h, const InboxLayout& layout, const SettledFn& settled,
                    const AgentOutput& out) {
  if (!h.retention.any()) return;
  const absl::StatusOr<PruneResult> r =
      Prune(layout, h.retention, settled, std::chrono::system_clock::now());
  if (!r.ok()) {
    Tell(out.warn, absl::StrCat("retention: ", r.status().message()));
    return;
  }
  if (r->heavy + r->light + r->archive > 0 || r->unsettled != h.unsettled)
    Tell(out.info, absl::StrCat("retention: ", PruneText(*r)));
  h.unsettled = r->unsettled;
}

}  // namespace surfinspect::client
