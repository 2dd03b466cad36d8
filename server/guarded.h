// The one guard at every callback that gRPC or the work pool invokes (reactor
// starts, reads, writes, pool jobs, finishes): it runs the callback and turns
// any exception into the status the call then finishes with, so no exception
// crosses an RPC or ends a pool thread.
//   std::bad_alloc         -> RESOURCE_EXHAUSTED ("out of memory in METHOD.STEP")
//   other std::exception   -> INTERNAL ("internal error: what()")
//   anything else (...)    -> INTERNAL ("internal error: unknown exception")
// Each caught exception also gets one log line naming METHOD.STEP.
// The test hook of server/fault_hook.h can make a guarded callback throw.
#pragma once

#include <grpcpp/support/status.h>

#include <exception>
#include <new>
#include <type_traits>

#include "server/fault_hook.h"

namespace surfinspect::server {

namespace guard_internal {
grpc::Status OutOfMemory(const char* method, const char* step);
grpc::Status Internal(const char* method, const char* step, const char* what);
}  // namespace guard_internal

// Runs `callback` (returning grpc::Status, or void = OK) for the callback
// METHOD.STEP; returns its status, or the status of the exception it threw.
template <typename Callback>
grpc::Status Guarded(const char* method, const char* step, Callback&& callback) {
  try {
    MaybeInjectFault(method, step);
    if constexpr (std::is_void_v<std::invoke_result_t<Callback&>>) {
      callback();
      return grpc::Status::OK;
    } else {
      return callback();
    }
  } catch (const std::bad_alloc&) {
    return guard_internal::OutOfMemory(method, step);
  } catch (const std::exception& e) {
    return guard_internal::Internal(method, step, e.what());
  } catch (...) {
    return guard_internal::Internal(method, step, "unknown exception");
  }
}

}  // namespace surfinspect::server
