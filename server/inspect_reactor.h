// InspectReactor: the state of one bidirectional Inspect stream. Reading
// side: part header (parsed once into typed settings), then per view a
// header and ~1 MB chunks, then the end marker, validated as they come
// (sizes against limits before any byte is buffered). Compute side: on the
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
#include "core/registration/registration.h"
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
  enum class State { kExpectPart, kExpectView, kInView, kEnded };
  // The stream's part header, parsed and validated once when it arrives.
  struct Part {
    std::string id;
    v1::MeshRef mesh;                        // indexed on the pool when inline
    std::shared_ptr<const MeshIndex> index;  // resolved at the header when sent by hash
    Eigen::Isometry3d world_from_part = Eigen::Isometry3d::Identity();
    InspectionSettings settings;
    bool return_deviations = false;
    bool return_png = false;
  };

  // Reading side.
  grpc::Status HandleRead(bool ok);
  grpc::Status Consume(v1::InspectRequest* msg);
  grpc::Status ConsumePart(v1::PartHeader* header);
  grpc::Status ConsumeView(const v1::ViewHeader& view);
  grpc::Status ConsumeChunk(const v1::CloudChunk& chunk);
  grpc::Status ConsumeEnd();
  grpc::Status IncompleteView(const std::string& field, const std::string& name) const;
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
  State state_ = State::kExpectPart;
  Part part_;
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
