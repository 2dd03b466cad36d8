#include "server/guarded.h"

#include <spdlog/spdlog.h>

#include <string>

namespace surfinspect::server::guard_internal {

grpc::Status OutOfMemory(const char* method, const char* step) {
  spdlog::error("{}.{}: std::bad_alloc caught; the call ends RESOURCE_EXHAUSTED", method, step);
  return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                      std::string("out of memory in ") + method + "." + step);
}

grpc::Status Internal(const char* method, const char* step, const char* what) {
  spdlog::error("{}.{}: exception caught ({}); the call ends INTERNAL", method, step, what);
  return grpc::Status(grpc::StatusCode::INTERNAL, std::string("internal error: ") + what);
}

}  // namespace surfinspect::server::guard_internal
