// The cell-agent's commands as a library (their flags are in
// client/agent/agent_flags.h): what each command wires together: `calibrate` (every viewpoint on
// the service, stored in cell.json), `verify` (a drift check), and `run` (the server connection,
// the simulated robot, MQTT events, the drift monitor and the results store around
// client/agent/agent.h's loop). Errors come back as statuses; client/agent/main.cpp holds the
// signals, the printing and the exit codes.
#pragma once

#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "client/agent/agent.h"
#include "client/agent/agent_flags.h"
#include "client/agent/calibrate_cell.h"
#include "client/agent/retention.h"
#include "client/agent/verify_cell.h"

namespace surfinspect::client {

// What the commands tell as they go, for a program to print or log.
struct AgentOutput {
  std::function<void(const std::string&)> info, warn, error;
  std::function<void(const ViewCalibration&)> calibrated;  // each viewpoint, as it ends
  std::function<void(const CellVerification&)> verified;   // each drift check
  std::function<void(const PartReport&)> part;             // each part, as it ends
  // The Inspect stream's progress of a part.
  std::function<void(const std::string& part_id, const v1::Progress&)> progress;
};

// Where verify's state goes: --status-dir, else beside cell.json.
std::string StatusDir(const AgentArgs& args);

struct CalibrateOutcome {
  std::size_t viewpoints = 0, calibrated = 0;
};
absl::StatusOr<CalibrateOutcome> RunCalibrateCommand(const AgentArgs& args, const AgentOutput& out,
                                                     std::atomic<bool>& stop);

// One drift check; its state is written to StatusDir.
absl::StatusOr<CellVerification> RunVerifyCommand(const AgentArgs& args, const AgentOutput& out);

struct RunOutcome {
  RunSummary summary;
  InboxLayout layout;
};
absl::StatusOr<RunOutcome> RunCellCommand(const AgentArgs& args, const AgentOutput& out,
                                          std::atomic<bool>& stop);

// cell.json's "retention" rule, applied once: the results store is caught
// up first, and a results folder is pruned only when the store (and the
// broker, where the cell has one) has the part.
absl::StatusOr<PruneResult> RunPruneCommand(const AgentArgs& args, const AgentOutput& out);

}  // namespace surfinspect::client
