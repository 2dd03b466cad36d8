// The one place core statuses become gRPC statuses. Core returns
// absl::Status; no exception ever crosses an RPC boundary.
#pragma once

#include <grpcpp/support/status.h>

#include "absl/status/status.h"

namespace surfinspect::server {

grpc::Status ToGrpc(const absl::Status& status);

// The code's name ("OK", "INVALID_ARGUMENT", ...) for logs and metrics.
const char* CodeName(grpc::StatusCode code);

// For validation failures that name a request field.
grpc::Status InvalidField(const std::string& field, const std::string& why);

}  // namespace surfinspect::server
