// One program run as a child process under limits: wall-clock time, address
// space, no core file, killed with its parent. For code that reads untrusted
// bytes and is not ours to harden (OpenCASCADE's STEP/IGES readers and
// mesher): whatever the child does, crash, hang or allocate without bound,
// the caller gets a status that says which.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"

namespace surfinspect {

struct ChildLimits {
  double seconds = 60;        // wall clock, then SIGKILL
  uint64_t memory_mb = 4096;  // RLIMIT_AS
};

// Runs argv[0] (a path) with argv; its stdout and stderr are one pipe, the
// tail of which (terminal colour codes removed) ends every error message.
// OK when it exits 0. Otherwise:
//   DeadlineExceeded  "<what> took longer than N s and was stopped"
//   ResourceExhausted "<what> ran out of its N MB memory limit" (exit code 3
//                     by convention, or an out-of-memory message on stderr)
//   Internal          "<what> crashed (signal N: NAME)"
//   the status the child named: exit code 2 is InvalidArgument (bad input),
//                     any other FailedPrecondition;
// each with the last lines the child wrote on stderr. NotFound when argv[0]
// cannot be run.
absl::Status RunLimited(const std::vector<std::string>& argv, const ChildLimits& limits,
                        const std::string& what);

}  // namespace surfinspect
