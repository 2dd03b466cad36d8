// InspectionService: the thin gRPC face of core. Each RPC parses and
// validates its request through proto/convert (naming the bad field), runs
// the core step on the work pool (admission control, shared TBB arena),
// builds the response through proto/convert, maps the core status through
// server/status_mapping, and logs and counts the call. Callback API: unary
// calls are HeavyCall reactors, Inspect is an InspectReactor
// (server/inspect_reactor.h) that holds the stream's state; every callback
// of either runs under Guarded (server/guarded.h), so an exception ends its
// call with a status instead of crossing the RPC.
#pragma once

#include <grpcpp/grpcpp.h>

#include <atomic>
#include <functional>
#include <memory>
#include <string>

#include "proto/convert.h"
#include "server/memory_budget.h"
#include "server/mesh_cache.h"
#include "server/metrics.h"
#include "server/work_pool.h"
#include "surfinspect/v1/inspection.grpc.pb.h"

namespace surfinspect::server {

struct ServiceConfig {
  wire::Limits limits;
  int threads = 2;              // worker threads = cores used by heavy calls
  int max_admitted_calls = 16;  // running + queued; more -> RESOURCE_EXHAUSTED
  std::size_t mesh_cache_bytes = std::size_t{512} << 20;
  // Bytes the calls may reserve at once (server/memory_budget.h); 0 = no
  // limit. RunServer fills in the default from the machine's limits.
  uint64_t memory_budget_bytes = 0;
  std::string auth_token;  // empty = no bearer-token check
  bool json_logs = false;
  // The largest message gRPC will send (--max-message-mb); a result over it
  // is refused by the service with the sizes, not lost in the transport.
  uint64_t max_message_bytes = uint64_t{64} << 20;
};

class InspectionService final : public v1::InspectionService::CallbackService {
 public:
  InspectionService(ServiceConfig config, Metrics* metrics);
  ~InspectionService() override;

  grpc::ServerUnaryReactor* Filter(grpc::CallbackServerContext* ctx, const v1::FilterRequest* req,
                                   v1::FilterResponse* resp) override;
  grpc::ServerUnaryReactor* Calibrate(grpc::CallbackServerContext* ctx,
                                      const v1::CalibrateRequest* req,
                                      v1::CalibrateResponse* resp) override;
  grpc::ServerUnaryReactor* Register(grpc::CallbackServerContext* ctx,
                                     const v1::RegisterRequest* req,
                                     v1::RegisterResponse* resp) override;
  grpc::ServerUnaryReactor* ErrorMap(grpc::CallbackServerContext* ctx,
                                     const v1::ErrorMapRequest* req,
                                     v1::ErrorMapResponse* resp) override;
  grpc::ServerBidiReactor<v1::InspectRequest, v1::InspectResponse>* Inspect(
      grpc::CallbackServerContext* ctx) override;

  // ---- shared by the reactors ----
  const ServiceConfig& config() const { return config_; }
  WorkPool& pool() { return pool_; }
  // Reserves what a call will hold, or RESOURCE_EXHAUSTED (with a retry
  // hint in the message) before the call buffers it.
  grpc::Status Reserve(uint64_t bytes, const std::string& what,
                       MemoryBudget::Reservation* reservation);
  Metrics* metrics() { return metrics_; }
  // UNAUTHENTICATED unless the call carries "authorization: Bearer <token>"
  // (when a token is configured).
  grpc::Status Authorize(const grpc::CallbackServerContext* ctx) const;
  // OK when `response` fits one message; else FAILED_PRECONDITION with its
  // size and the limit. Not retryable: the same request gives the same size.
  grpc::Status FitsOneMessage(const google::protobuf::MessageLite& response,
                              const char* what) const;
  // Inline mesh: validated, indexed and cached under its hash. By hash: from
  // the cache, or FAILED_PRECONDITION "MESH_NOT_CACHED" (+ trailer).
  grpc::Status ResolveMesh(grpc::CallbackServerContext* ctx, const v1::MeshRef& ref,
                           const std::string& field, std::shared_ptr<const MeshIndex>* out);
  // Request id: the client's x-request-id, or a generated one.
  std::string RequestId(const grpc::CallbackServerContext* ctx);
  // `stop_ms`: for a cancelled call, how long its work ran on after the
  // cancellation (NaN otherwise).
  void LogCall(const std::string& request_id, const std::string& method, const std::string& peer,
               uint64_t points, const grpc::Status& status, double seconds, double stop_ms = NAN);

 private:
  using Work = std::function<grpc::Status(const std::atomic<bool>& cancel)>;
  grpc::ServerUnaryReactor* RunHeavy(grpc::CallbackServerContext* ctx, const char* method,
                                     uint64_t points, Work work);

  ServiceConfig config_;
  Metrics* metrics_;
  MeshCache mesh_cache_;
  MemoryBudget budget_;
  std::atomic<uint64_t> next_request_{1};
  WorkPool pool_;  // last: joined first on destruction, before the cache goes
};

}  // namespace surfinspect::server
