// RemoteClient: the client side of surfinspect.v1, shared by the CLI's
// --server mode and the cell-agent. It owns the channel (TLS, bearer token,
// round_robin over several replicas), sends a mesh inline when it is small
// next to the call's clouds (at most 1/8 of their bytes), else by content
// hash, re-sent inline when a replica answers MESH_NOT_CACHED; streams whole
// parts in ~1 MB chunks, and maps gRPC statuses back to absl statuses.
#pragma once

#include <grpcpp/grpcpp.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/registration/registration.h"
#include "core/types/triangle_mesh.h"
#include "surfinspect/v1/inspection.grpc.pb.h"

namespace surfinspect::client {

namespace v1 = ::surfinspect::v1;

struct RemoteOptions {
  // Any gRPC target: "host:port", "dns:///svc:50051",
  // "ipv4:127.0.0.1:50051,127.0.0.1:50052" (then round_robin spreads calls).
  std::string target;
  std::string tls_ca_file;            // set = TLS, verifying the server with this CA
  std::string tls_cert_file;          // client certificate (mTLS) ...
  std::string tls_key_file;           // ... and its key
  std::string tls_server_name;        // override the name checked in the server cert
  std::string auth_token;             // sent as "authorization: Bearer <token>"
  double timeout_s = 600;             // per call
  std::size_t chunk_bytes = 1 << 20;  // Inspect chunk size
};

// gRPC status -> absl status (same code, same message).
absl::Status FromGrpc(const grpc::Status& status);
// Codes worth retrying with backoff: UNAVAILABLE, RESOURCE_EXHAUSTED,
// DEADLINE_EXCEEDED, ABORTED (and INTERNAL from a dying replica is not).
bool IsRetryable(const absl::Status& status);

class RemoteClient {
 public:
  static absl::StatusOr<std::unique_ptr<RemoteClient>> Connect(const RemoteOptions& options);

  absl::StatusOr<v1::FilterResponse> Filter(const v1::FilterRequest& request);
  // `gauge`/`part` fill the request's mesh: inline when small, else by hash
  // first and inline on a miss.
  absl::StatusOr<v1::CalibrateResponse> Calibrate(v1::CalibrateRequest request,
                                                  const TriangleMesh& gauge);
  absl::StatusOr<v1::RegisterResponse> Register(v1::RegisterRequest request,
                                                const TriangleMesh* part);
  absl::StatusOr<v1::ErrorMapResponse> ErrorMap(v1::ErrorMapRequest request,
                                                const TriangleMesh& part);

  using ProgressFn = std::function<void(const v1::Progress&)>;
  // Streams a whole part; `header.part` is filled from `part`.
  absl::StatusOr<v1::InspectResult> Inspect(v1::PartHeader header, const TriangleMesh& part,
                                            const std::vector<ViewScan>& views,
                                            const ProgressFn& progress = {});

  // grpc.health.v1 status of `service` ("" = the whole server):
  // "SERVING", "NOT_SERVING", ... or an error.
  absl::StatusOr<std::string> Health(const std::string& service = "");

  // Whether the server answers at all, asked by a health check that does
  // not wait for a connection (so a refused one fails at once, one without
  // an answer after 3 s), repeated every 0.25 s for up to `wait_s` (0:
  // once). A call waits for a connection until its deadline, so without
  // this a wrong address or a server that is down would be told only after
  // --timeout, as "Deadline Exceeded". Unavailable "cannot reach
  // surfinspectd at TARGET: <gRPC's reason, e.g. Connection refused>".
  // `waiting` is told the reason once when the first try fails and there
  // is time left to wait.
  absl::Status WaitUntilReachable(double wait_s,
                                  const std::function<void(const std::string&)>& waiting = {});
  const std::string& target() const { return options_.target; }

 private:
  RemoteClient(const RemoteOptions& options, std::shared_ptr<grpc::Channel> channel,
               std::shared_ptr<grpc::Channel> probe_channel);
  void Prepare(grpc::ClientContext* ctx) const;
  // One unary call of the stub's `rpc` with this client's deadline and token.
  template <typename Request, typename Response>
  absl::StatusOr<Response> Unary(grpc::Status (v1::InspectionService::Stub::*rpc)(
                                     grpc::ClientContext*, const Request&, Response*),
                                 const Request& request);
  absl::StatusOr<v1::InspectResult> InspectOnce(const v1::PartHeader& header,
                                                const std::vector<ViewScan>& views,
                                                const ProgressFn& progress);

  RemoteOptions options_;
  std::shared_ptr<grpc::Channel> channel_;
  // WaitUntilReachable's own channel: a probe on `channel_` would take a
  // round_robin pick, and one probe before each part would then send every
  // part to the same replica of two.
  std::shared_ptr<grpc::Channel> probe_channel_;
  std::unique_ptr<v1::InspectionService::Stub> stub_;
};

// True when a status is the server's MESH_NOT_CACHED answer.
bool IsMeshNotCached(const absl::Status& status);

}  // namespace surfinspect::client
