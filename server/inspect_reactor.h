// InspectReactor: the state of one bidirectional Inspect stream. Reading
// side: wire::InspectStreamReader (proto/inspect_stream.h) takes the part
// header, the view headers with their ~1 MB chunks and the end marker,
// validated as they come; the reactor's hooks look a mesh up by hash,
// reserve each view's memory and report each view received. Compute side: on the
// work pool, InspectPart (core/pipeline/inspection) with progress events
// streamed back, then the result. Writes go through a queue (one outstanding
// write at a time); Finish happens exactly once, and never while the pool job
// still uses the reactor. Every callback runs under Guarded
// (server/guarded.h): an exception ends the stream with its status.
#pragma once

#include <grpcpp/grpcpp.h>

#include <Eigen/Geometry>
#include <atomic>
#include <chrono>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/pipeline/inspection.h"
#include "proto/inspect_stream.h"
#include "server/cancel_signal.h"
#include "server/inspection_service.h"

namespace surfinspect::server {

class InspectReactor final
    : public grpc::ServerBidiReactor<v1::InspectRequest, v1::InspectResponse> {
 public:
  InspectReactor(InspectionService* service, grpc::CallbackServerContext* ctx);
  // Authorizes and starts the first read; called once, right after construction.
  void Start();
  void OnReadDone(bool ok) override;
  void OnWriteDone(bool ok) override;
  void OnCancel() override { cancel_.Raise(); }
  void OnDone() override { delete this; }

 private:
  // Reading side.
  grpc::Status HandleRead(bool ok);
  grpc::Status Consume(v1::InspectRequest* msg);
  wire::InspectStreamReader::Hooks ReaderHooks();
  grpc::Status SubmitComputeLocked();
  // Compute side (the pool job).
  void Compute();
  grpc::Status RunInspection();
  // Writing side and finish bookkeeping.
  void Send(v1::InspectResponse msg);
  void SendProgress(v1::Progress::Stage stage, const std::string& view, uint64_t points,
                    const std::string& detail = "");
  void StartNextWriteLocked(bool ok);
  void RequestFinish(const grpc::Status& st);
  void RequestFinishLocked(const grpc::Status& st);
  void MaybeFinishLocked();
  void LogAndCountLocked();

  // First members, so they are released last: after the views' clouds.
  std::vector<MemoryBudget::Reservation> reserved_;
  InspectionService* service_;
  grpc::CallbackServerContext* ctx_;
  std::string request_id_;
  std::chrono::steady_clock::time_point start_;
  CancelSignal cancel_;

  // Reading side (only touched by OnReadDone, which gRPC serialises, and then
  // by the pool job, which starts after the last read).
  v1::InspectRequest in_;
  wire::InspectStreamReader reader_;             // the part header and the views
  std::shared_ptr<const MeshIndex> part_index_;  // resolved at the header when sent by hash
  grpc::Status hook_status_;                     // a hook's own failure, returned as it is

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
