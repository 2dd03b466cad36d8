// cell-agent: runs at the robot cell. `calibrate` fits every viewpoint's
// gauge scan on the service and stores the results in cell.json; `run`
// watches the inbox, streams each complete part to Inspect, writes the
// results, and archives the scans; `verify` checks the calibration for
// drift; `prune` applies the retention rule. What each command does is
// client/agent/agent_command.h; this file holds the signals, the printing
// and the exit codes.
#include <signal.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <cstdio>

#include "client/agent/agent_command.h"
#include "client/agent/inbox.h"
#include "core/process/buffer_reuse.h"

namespace surfinspect::client {
namespace {

std::atomic<bool> g_stop{false};
void OnSignal(int) { g_stop.store(true); }

void PrintCalibration(const ViewCalibration& v) {
  if (!v.status.ok()) {
    spdlog::error("{}: {}", v.name, std::string(v.status.message()));
    return;
  }
  const v1::CalibrationQuality& q = v.response.quality();
  std::printf("%-8s %10.4f %12.2f %12.5f %6u %10s\n", v.name.c_str(), q.rms_mm(),
              q.sigma_translation_um(), q.sigma_rotation_deg(), q.iterations(),
              q.degenerate() ? "YES" : "no");
  for (const auto& w : q.warnings()) spdlog::warn("{}: {}", v.name, w);
}

void PrintVerification(const CellVerification& v) {
  std::printf("%-8s %12s %12s %12s %10s %6s\n", "view", "part_um", "sensor_um", "rotation_deg",
              "sigma", "state");
  for (const auto& w : v.views) {
    if (!w.status.ok()) {
      std::printf("%-8s %s\n", w.name.c_str(), std::string(w.status.message()).c_str());
      continue;
    }
    std::printf("%-8s %12.2f %12.2f %12.5f %10.1f %6s\n", w.name.c_str(), w.drift.at_part_um,
                w.drift.at_sensor_um, w.drift.rotation_deg, w.drift.significance,
                DriftClassName(w.drift.verdict));
  }
  std::fflush(stdout);
}

void PrintPart(const PartReport& r) {
  if (isatty(STDERR_FILENO)) std::fprintf(stderr, "\r%*s\r", 60, "");  // the progress line
  switch (r.outcome) {
    case PartOutcome::kDone:
      std::printf("%-16s %-4s  max %+.3f mm  min %+.3f mm  %.1f s\n", r.part_id.c_str(),
                  r.verdict.c_str(), r.max_mm, r.min_mm, r.seconds);
      std::fflush(stdout);
      if (!r.message.empty()) spdlog::error("{}: results written; {}", r.part_id, r.message);
      break;
    case PartOutcome::kArchivedWithoutCall:
    case PartOutcome::kStopped:
      spdlog::info("{}: {}", r.part_id, r.message);
      break;
    case PartOutcome::kQuarantined:
      spdlog::error("{}: {} -> quarantine", r.part_id, r.message);
      break;
    case PartOutcome::kRetryLater:
      spdlog::error("{}: {} (left in the inbox; retried later)", r.part_id, r.message);
      break;
    case PartOutcome::kConfigError:
      spdlog::error("{}: {}", r.part_id, r.message);
      break;
  }
}

// Logs, tables, and the Inspect stream's progress on a terminal.
AgentOutput Printing() {
  AgentOutput out;
  out.info = [](const std::string& m) { spdlog::info("{}", m); };
  out.warn = [](const std::string& m) { spdlog::warn("{}", m); };
  out.error = [](const std::string& m) { spdlog::error("{}", m); };
  out.calibrated = PrintCalibration;
  out.verified = PrintVerification;
  out.part = PrintPart;
  if (isatty(STDERR_FILENO))
    out.progress = [](const std::string& part_id, const v1::Progress& p) {
      std::fprintf(stderr, "\r  %s: %-24s %-6s      \r", part_id.c_str(),
                   v1::Progress::Stage_Name(p.stage()).c_str(), p.view().c_str());
    };
  return out;
}

// A command's error: logged, exit code 2 (configuration).
template <typename T>
bool Failed(const absl::StatusOr<T>& r) {
  if (r.ok()) return false;
  spdlog::error("{}", std::string(r.status().message()));
  return true;
}

int Calibrate(const AgentArgs& a) {
  std::printf("%-8s %10s %12s %12s %6s %10s\n", "view", "rms_mm", "sigma_t_um", "sigma_r_deg",
              "iters", "degenerate");
  const auto r = RunCalibrateCommand(a, Printing(), g_stop);
  if (Failed(r)) return 2;
  std::printf("calibrated %zu of %zu viewpoints -> %s (previous kept as %s.bak)\n", r->calibrated,
              r->viewpoints, a.cell.c_str(), a.cell.c_str());
  return r->calibrated == r->viewpoints ? 0 : 1;
}

int Verify(const AgentArgs& a) {
  const auto v = RunVerifyCommand(a, Printing());
  if (Failed(v)) return 2;
  std::printf("calibration %s: %s (state in %s/calibration_status.json)\n",
              DriftClassName(v->verdict), v->reason.c_str(), StatusDir(a).c_str());
  return v->verdict == DriftClass::kFail ? 3 : 0;
}

// The run's last lines, and the exit code: 0, or 2 (configuration), 3 (parts
// quarantined), 4 (stopped by a failed drift check).
int Run(const AgentArgs& a) {
  const auto r = RunCellCommand(a, Printing(), g_stop);
  if (Failed(r)) return 2;
  const RunSummary& s = r->summary;
  const InboxLayout& layout = r->layout;
  if (s.config_error) return 2;
  if (!s.halted.empty()) {
    spdlog::error(
        "stopped inspecting: {}; {} parts left in {} (state in {}/calibration_status.json)",
        s.halted, CompleteParts(layout.inbox).size(), layout.inbox, StatusDir(a));
    return 4;
  }
  std::printf("summary: %d parts done (%d pass, %d fail), ", s.done, s.pass, s.done - s.pass);
  if (s.archived_without_call > 0)
    std::printf("%d archived with earlier results, ", s.archived_without_call);
  std::printf("%d quarantined, %zu left in %s\n", s.quarantined, CompleteParts(layout.inbox).size(),
              layout.inbox.c_str());
  return s.quarantined == 0 ? 0 : 3;
}

int Prune(const AgentArgs& a) {
  const auto r = RunPruneCommand(a, Printing());
  if (Failed(r)) return 2;
  std::printf("%s\n", PruneText(*r).c_str());
  return 0;
}

}  // namespace
}  // namespace surfinspect::client

int main(int argc, char** argv) {
  using namespace surfinspect::client;
  surfinspect::ReuseFreedLargeBuffers();  // clouds are ~10 MB buffers, over and over
  spdlog::set_default_logger(spdlog::stderr_color_mt("cell-agent"));
  AgentArgs a;
  CLI::App app{"cell-agent: streams a robot cell's scans to surfinspectd and keeps the results"};
  const AgentCommands commands = AddAgentCommands(app, a);
  CLI11_PARSE(app, argc, argv);
  signal(SIGTERM, OnSignal);
  signal(SIGINT, OnSignal);
  if (commands.calibrate->parsed()) return Calibrate(a);
  if (commands.verify->parsed()) return Verify(a);
  if (commands.prune->parsed()) return Prune(a);
  return Run(a);
}
