// Each CLI subcommand registers itself on the app; its callback throws
// CommandFailed with a message, which main() prints and maps to exit code 1.
#pragma once

#include <CLI/CLI.hpp>
#include <stdexcept>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace surfinspect::cli {

struct CommandFailed : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Unwraps a status or throws CommandFailed carrying its message.
inline void Check(const absl::Status& st) {
  if (!st.ok()) throw CommandFailed(std::string(st.message()));
}
template <typename T>
T Take(absl::StatusOr<T> v) {
  if (!v.ok()) throw CommandFailed(std::string(v.status().message()));
  return *std::move(v);
}

void AddInfoCommand(CLI::App& app);
void AddFilterCommand(CLI::App& app);
void AddSimulateCommands(CLI::App& app);
void AddCalibrateCommand(CLI::App& app);
void AddRegisterCommand(CLI::App& app);
void AddInspectCommand(CLI::App& app);
void AddHealthCommand(CLI::App& app);
void AddErrorMapCommand(CLI::App& app);
void AddAcceptanceCommand(CLI::App& app);
void AddTrendCommand(CLI::App& app);
void AddCadCommand(CLI::App& app);
void AddHolesCommand(CLI::App& app);

}  // namespace surfinspect::cli
