// Test hook: makes a guarded callback (server/guarded.h) throw, so tests can
// prove that an exception inside a reactor or pool callback ends that one call
// with a status and leaves the server serving. Off unless surfinspectd is
// started with `--fault-inject KIND:SITE[:COUNT]`; while off, each check is
// one relaxed atomic load.
//   KIND:  bad_alloc (std::bad_alloc), runtime_error (std::runtime_error),
//          unknown (an int, caught only by `catch (...)`).
//   SITE:  METHOD.STEP, the name the guard logs: Inspect.Start,
//          Inspect.OnReadDone, Inspect.OnWriteDone, Inspect.Compute,
//          Inspect.Finish, and for Filter, Calibrate, Register and ErrorMap
//          METHOD.Start, METHOD.Run, METHOD.Done.
//   COUNT: how many calls of SITE throw (default 1); later calls run normally.
#pragma once

#include <atomic>
#include <string>

#include "absl/status/status.h"

namespace surfinspect::server {

// Arms one fault, process-wide. InvalidArgument names a bad KIND, SITE or COUNT.
absl::Status ArmFault(const std::string& spec);

namespace fault_internal {
extern std::atomic<bool> armed;
void InjectIfArmed(const char* method, const char* step);
}  // namespace fault_internal

// Throws when a fault armed for METHOD.STEP has calls left; otherwise returns.
inline void MaybeInjectFault(const char* method, const char* step) {
  if (fault_internal::armed.load(std::memory_order_relaxed))
    fault_internal::InjectIfArmed(method, step);
}

}  // namespace surfinspect::server
