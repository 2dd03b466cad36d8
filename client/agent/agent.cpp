#include "client/agent/agent.h"

#include <chrono>
#include <filesystem>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "client/cell/cell_part.h"
#include "client/cell/part_outputs.h"
#include "client/cell/report_context.h"
#include "core/io/disk_space.h"
#include "core/io/io_mesh.h"
#include "core/io/io_point_cloud.h"

namespace surfinspect::client {
namespace fs = std::filesystem;
namespace {

// The folder that holds `inbox` (absolute; a trailing separator ignored).
fs::path BesideInbox(const std::string& inbox, const char* name) {
  std::error_code ec;
  fs::path p = fs::absolute(fs::path(inbox), ec);
  if (ec) p = fs::path(inbox);
  p = p.lexically_normal();
  if (p.filename().empty()) p = p.parent_path();
  return p.parent_path() / name;
}

PartReport Report(PartOutcome outcome, std::string message) {
  PartReport r;
  r.outcome = outcome;
  r.message = std::move(message);
  return r;
}

}  // namespace

InboxLayout ResolveLayout(const AgentPaths& p) {
  const auto below = [&](const std::string& given, const char* name, const std::string& dflt) {
    if (!given.empty()) return given;
    if (!p.cell_dir.empty()) return (fs::path(p.cell_dir) / name).string();
    return dflt;
  };
  InboxLayout l;
  l.inbox = below(p.inbox, "inbox", "inbox");
  l.results = below(p.results, "results", "results");
  l.archive = below(p.archive, "archive", BesideInbox(l.inbox, "archive").string());
  l.quarantine = below(p.quarantine, "quarantine", BesideInbox(l.inbox, "quarantine").string());
  return l;
}

absl::Status PrepareDirectories(const InboxLayout& layout) {
  for (const auto& d : {layout.inbox, layout.results}) {
    std::error_code ec;
    fs::create_directories(d, ec);
    if (ec)
      return absl::PermissionDeniedError(absl::StrCat("cannot create ", d, ": ", ec.message()));
  }
  return absl::OkStatus();
}

const char* PartOutcomeName(PartOutcome outcome) {
  switch (outcome) {
    case PartOutcome::kDone:
      return "done";
    case PartOutcome::kArchivedWithoutCall:
      return "archived without call";
    case PartOutcome::kQuarantined:
      return "quarantined";
    case PartOutcome::kRetryLater:
      return "retry later";
    case PartOutcome::kStopped:
      return "stopped";
    case PartOutcome::kConfigError:
      return "config error";
  }
  return "?";
}

CellAgent::CellAgent(const CellConfig& cell, InboxLayout layout, AgentSettings settings,
                     AgentHooks hooks, uint64_t seed)
    : cell_(cell),
      layout_(std::move(layout)),
      settings_(settings),
      hooks_(std::move(hooks)),
      rng_(seed) {}

PartReport CellAgent::ProcessPart(const std::string& part_id, const std::atomic<bool>& stop) {
  const auto t0 = std::chrono::steady_clock::now();
  PartReport r = Steps(part_id, stop);
  r.part_id = part_id;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

PartReport CellAgent::Steps(const std::string& id, const std::atomic<bool>& stop) {
  if (!IsValidPartId(id)) return QuarantinePart(id, "invalid part id (use letters, digits, . _ -)");
  // Judged before and the move failed: move again, never send again.
  if (auto it = quarantine_pending_.find(id); it != quarantine_pending_.end())
    return QuarantinePart(id, it->second);
  if (HasResults(layout_, id)) return ArchiveWithoutCall(id);  // never send twice
  std::vector<ViewScan> views;
  PartReport ended;
  if (!ReadViews(id, &views, &ended)) return ended;
  for (const auto& listener : hooks_.on_started) listener(id);
  return InspectAndStore(id, views, stop);
}

PartReport CellAgent::QuarantinePart(const std::string& id, std::string why) {
  if (absl::Status st = Quarantine(layout_, id, why); !st.ok()) {
    quarantine_pending_[id] = why;
    return Report(PartOutcome::kRetryLater,
                  absl::StrCat("cannot quarantine (", why, "): ", st.message()));
  }
  quarantine_pending_.erase(id);
  return Report(PartOutcome::kQuarantined, why);
}

std::shared_ptr<const TriangleMesh> CellAgent::PartMesh() {
  if (!part_mesh_read_) {
    part_mesh_read_ = true;
    if (auto mesh = ReadCellPartMesh(cell_); mesh.ok())
      part_mesh_ = std::make_shared<const TriangleMesh>(*std::move(mesh));
  }
  return part_mesh_;
}

bool CellAgent::HasRoom() {
  if (hooks_.disk == nullptr) return true;
  const absl::Status room = hooks_.disk->Check();
  SetDiskFull(room.ok() ? "" : std::string(room.message()));
  return room.ok();
}

void CellAgent::SetDiskFull(const std::string& reason) {
  const bool changed = reason.empty() != disk_full_.empty();
  disk_full_ = reason;
  if (changed)
    for (const auto& listener : hooks_.on_disk) listener(reason);
}

void CellAgent::TellStored(const std::string& id) const {
  const std::string dir = (fs::path(layout_.results) / id).string();
  for (const auto& listener : hooks_.on_stored) listener(id, dir);
}

PartReport CellAgent::ArchiveWithoutCall(const std::string& id) {
  TellStored(id);
  if (absl::Status st = MovePart(layout_.inbox, layout_.archive, id); !st.ok())
    return Report(PartOutcome::kRetryLater,
                  absl::StrCat("results already on disk; ", st.message()));
  return Report(PartOutcome::kArchivedWithoutCall, "results already on disk; archived");
}

bool CellAgent::ReadViews(const std::string& id, std::vector<ViewScan>* views, PartReport* report) {
  std::vector<std::string> doubts;
  for (const auto& vp : cell_.viewpoints) {
    const std::string path = (fs::path(layout_.inbox) / id / (vp.name + ".pcd")).string();
    if (!fs::exists(path)) continue;
    auto cloud = ReadCellScan(cell_, path, PartMesh().get(), &doubts);
    if (!cloud.ok()) {
      *report = QuarantinePart(id, std::string(cloud.status().message()));
      return false;
    }
    if (!vp.world_from_sensor) {
      *report = Report(
          PartOutcome::kConfigError,
          absl::StrCat("viewpoint ", vp.name, " is not calibrated; run cell-agent calibrate"));
      return false;
    }
    views->push_back({vp.name, *std::move(cloud), *vp.world_from_sensor});
  }
  if (views->empty()) {
    *report = QuarantinePart(id, "no <viewpoint>.pcd scan of this cell's viewpoints");
    return false;
  }
  // Units in doubt would give deviations off by their factor: never judged.
  if (!doubts.empty()) {
    *report = QuarantinePart(id, absl::StrCat("units in doubt: ", absl::StrJoin(doubts, "; ")));
    return false;
  }
  return true;
}

PartReport CellAgent::InspectAndStore(const std::string& id, const std::vector<ViewScan>& views,
                                      const std::atomic<bool>& stop) {
  const v1::PartHeader header =
      MakePartHeader(id, cell_.world_from_part, InspectionSettingsOf(cell_));
  absl::StatusOr<v1::InspectResult> result = absl::UnknownError("not sent");
  RetryHooks retry{hooks_.sleep, {}};
  if (hooks_.on_retry)
    retry.on_retry = [&](const absl::Status& st, int calls, double wait_s) {
      hooks_.on_retry(id, st, calls, wait_s);
    };
  const RetryResult rr = RetryWithBackoff(
      [&] {
        result = hooks_.inspect(header, views);
        return result.status();
      },
      IsRetryable, settings_.backoff, retry, rng_, stop);
  PartReport r;
  if (rr.end == RetryEnd::kStopped) {
    r = Report(PartOutcome::kStopped, "stop requested; left in the inbox");
  } else if (rr.end == RetryEnd::kExhausted) {
    r = Report(PartOutcome::kRetryLater,
               absl::StrCat("gave up after ", rr.calls, " attempts: ", rr.status.message()));
  } else if (rr.end == RetryEnd::kFailed) {
    r = QuarantinePart(
        id, absl::StrCat(absl::StatusCodeToString(rr.status.code()), ": ", rr.status.message()));
  } else {
    auto outputs = OutputsFromRemote(*result);
    if (outputs.ok()) {
      outputs->cell = cell_.name;
      outputs->world_from_part = cell_.world_from_part;
      outputs->mesh_in_part = PartMesh();
      outputs->viewpoints = ViewpointCalibrations(cell_);
      if (cell_.part_cad) outputs->cad = ReportCadOf(*cell_.part_cad);
      outputs->input_units = CellInputUnits(cell_, {});
    }
    uint64_t bytes = 0;
    absl::Status written = outputs.ok()
                               ? WritePartOutputs((fs::path(layout_.results) / id).string(),
                                                  *outputs, cell_.outputs, &bytes)
                               : outputs.status();
    if (hooks_.disk != nullptr && written.ok()) hooks_.disk->SetWritten(bytes);
    if (hooks_.disk != nullptr && IsDiskFull(written)) {
      hooks_.disk->SetFailed(bytes);
      SetDiskFull(std::string(written.message()));
    }
    if (!written.ok()) {  // disk trouble: keep the part in the inbox for the next pass
      r = Report(PartOutcome::kRetryLater,
                 absl::StrCat("cannot write results: ", written.message()));
    } else {
      r.outcome = PartOutcome::kDone;
      r.verdict = outputs->verdict;
      r.min_mm = outputs->min_mm;
      r.max_mm = outputs->max_mm;
      TellStored(id);
      // The results are safe; the next pass archives it without a call.
      if (absl::Status st = MovePart(layout_.inbox, layout_.archive, id); !st.ok())
        r.message = std::string(st.message());
    }
  }
  r.inspect_calls = rr.calls;
  return r;
}

RunSummary CellAgent::Run(const std::atomic<bool>& stop,
                          const std::function<void(const PartReport&)>& on_part) {
  RunSummary s;
  while (!stop.load()) {
    bool progressed = false;
    for (const auto& id : CompleteParts(layout_.inbox)) {
      if (stop.load()) break;
      if (!HasRoom()) break;  // paused: the parts wait in the inbox
      if (hooks_.before_part)
        if (absl::Status st = hooks_.before_part(s.done); !st.ok()) {
          s.halted = std::string(st.message());
          return s;
        }
      const PartReport r = ProcessPart(id, stop);
      if (on_part) on_part(r);
      switch (r.outcome) {
        case PartOutcome::kDone:
          ++s.done;
          s.pass += r.verdict == "pass" ? 1 : 0;
          progressed = true;
          break;
        case PartOutcome::kArchivedWithoutCall:
          ++s.archived_without_call;
          progressed = true;
          break;
        case PartOutcome::kQuarantined:
          ++s.quarantined;
          progressed = true;
          break;
        case PartOutcome::kConfigError:
          s.config_error = true;
          return s;
        case PartOutcome::kRetryLater:
        case PartOutcome::kStopped:
          break;
      }
      if (!disk_full_.empty()) break;  // the part's write found the disk full
    }
    if (settings_.once && (!progressed || CompleteParts(layout_.inbox).empty())) break;
    if (!progressed && !stop.load()) hooks_.sleep(settings_.poll_s, stop);
  }
  return s;
}

}  // namespace surfinspect::client
