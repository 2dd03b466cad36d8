// The one mapping from absl::Status (what core and proto/convert return) to
// grpc::Status: each absl code becomes the gRPC code of the same name, the
// message is kept, and an unknown code becomes INTERNAL. Exceptions never
// reach it: server/guarded.h turns them into statuses at every callback.
#pragma once

#include <grpcpp/support/status.h>

#include <string>

#include "absl/status/status.h"

namespace surfinspect::server {

grpc::Status ToGrpc(const absl::Status& status);

// The code's name ("OK", "INVALID_ARGUMENT", ...) for logs and metrics.
const char* CodeName(grpc::StatusCode code);

// For validation failures that name a request field.
grpc::Status InvalidField(const std::string& field, const std::string& why);

}  // namespace surfinspect::server
