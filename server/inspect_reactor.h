// InspectReactor: the state of one bidirectional Inspect stream. Reading
// side: part header, then per view a header and ~1 MB chunks, then the end
// marker, validated as they come (sizes against limits before any byte is
// buffered). Compute side: on the work pool, InspectPart (core/inspection)
// with progress events streamed back, then the result. Writes go through a
// queue (one outstanding write at a time); Finish happens exactly once, and
// never while the pool job still uses the reactor.
#pragma once

#include <grpcpp/grpcpp.h>

#include <atomic>
#include <chrono>
#include <deque>
#include <mutex>
#include <string>
#include <vector>

#include "core/registration/registration.h"
#include "server/cancel_signal.h"
#include "server/inspection_service.h"

namespace surfinspect::server {

class InspectReactor final
    : public grpc::ServerBidiReactor<v1::InspectRequest, v1::InspectResponse> {
 public:
  InspectReactor(InspectionService* service, grpc::CallbackServerContext* ctx);
  void OnReadDone(bool ok) override;
  void OnWriteDone(bool ok) override;
  void OnCancel() override { cancel_.Raise(); }
  void OnDone() override { delete this; }

 private:
  enum class State { kExpectPart, kExpectView, kInView, kEnded };
  grpc::Status Consume(const v1::InspectRequest& msg);
  void Compute();
  void Send(v1::InspectResponse msg);
  void SendProgress(v1::Progress::Stage stage, const std::string& view, uint64_t points,
                    const std::string& detail = "");
  void RequestFinish(const grpc::Status& st);
  void MaybeFinishLocked();

  InspectionService* service_;
  grpc::CallbackServerContext* ctx_;
  std::string request_id_;
  std::chrono::steady_clock::time_point start_;
  CancelSignal cancel_;

  // Reading side (only touched by OnReadDone, which gRPC serialises).
  v1::InspectRequest in_;
  State state_ = State::kExpectPart;
  v1::PartHeader header_;
  std::shared_ptr<const MeshIndex> part_;  // resolved at the header when sent by hash
  std::vector<ViewScan> views_;
  wire::CloudAssembler view_cloud_;  // the view whose chunks are arriving
  uint64_t total_points_ = 0;

  // Writing side and finish bookkeeping.
  std::mutex mu_;
  std::deque<v1::InspectResponse> out_;
  bool writing_ = false;
  bool computing_ = false;
  bool finish_requested_ = false;
  bool finished_ = false;
  bool admitted_ = false;
  grpc::Status final_status_;
};

}  // namespace surfinspect::server
