#include "server/inspect_reactor.h"

#include "absl/strings/str_cat.h"
#include "core/report/error_map_png.h"
#include "server/guarded.h"
#include "server/status_mapping.h"

namespace surfinspect::server {

InspectReactor::InspectReactor(InspectionService* service, grpc::CallbackServerContext* ctx)
    : service_(service),
      ctx_(ctx),
      request_id_(service->RequestId(ctx)),
      start_(std::chrono::steady_clock::now()),
      reader_(service->config().limits, ReaderHooks()) {}

grpc::ServerBidiReactor<v1::InspectRequest, v1::InspectResponse>* InspectionService::Inspect(
    grpc::CallbackServerContext* ctx) {
  auto* reactor = new InspectReactor(this, ctx);
  reactor->Start();
  return reactor;
}

void InspectReactor::Start() {
  const grpc::Status st = Guarded("Inspect", "Start", [this] {
    if (grpc::Status auth = service_->Authorize(ctx_); !auth.ok()) return auth;
    StartRead(&in_);
    return grpc::Status::OK;
  });
  if (!st.ok()) RequestFinish(st);
}

// ---- reading side ----

void InspectReactor::OnReadDone(bool ok) {
  const grpc::Status st = Guarded("Inspect", "OnReadDone", [&] { return HandleRead(ok); });
  if (!st.ok()) RequestFinish(st);
}

// OK while the stream goes on: the next read, or the pool job, is started.
// Both are started under mu_ and only while no finish is requested (a failed
// write may request one concurrently), so nothing starts after Finish.
grpc::Status InspectReactor::HandleRead(bool ok) {
  if (!ok)  // the client closed its side (or the call died) before the end marker
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, "stream closed before EndOfPart");
  if (grpc::Status st = Consume(&in_); !st.ok()) return st;
  std::lock_guard<std::mutex> lock(mu_);
  if (finish_requested_) return grpc::Status::OK;
  if (!reader_.ended()) {
    StartRead(&in_);
    return grpc::Status::OK;
  }
  return SubmitComputeLocked();
}

// A hook's own grpc::Status (its code, message and trailing metadata as the
// service set them) is returned as it is; the reader's statuses go through ToGrpc.
grpc::Status InspectReactor::Consume(v1::InspectRequest* msg) {
  hook_status_ = grpc::Status::OK;
  const absl::Status st = reader_.Consume(msg);
  if (st.ok()) return grpc::Status::OK;
  return hook_status_.ok() ? ToGrpc(st) : hook_status_;
}

wire::InspectStreamReader::Hooks InspectReactor::ReaderHooks() {
  wire::InspectStreamReader::Hooks hooks;
  hooks.resolve_mesh = [this](const v1::MeshRef& mesh, const std::string& field) {
    hook_status_ = service_->ResolveMesh(ctx_, mesh, field, &part_index_);
    return hook_status_.ok() ? absl::OkStatus() : absl::AbortedError("resolve_mesh");
  };
  hooks.reserve_view = [this](uint64_t view_points, const std::string& view_name) {
    hook_status_ = service_->Reserve(
        view_points * InspectBytesPerPoint(),
        absl::StrCat("Inspect part '", reader_.part().id, "' view '", view_name, "'"),
        &reserved_.emplace_back());
    return hook_status_.ok() ? absl::OkStatus() : absl::AbortedError("reserve_view");
  };
  hooks.view_received = [this](const std::string& view_name, uint64_t points) {
    SendProgress(v1::Progress::STAGE_VIEW_RECEIVED, view_name, points);
  };
  return hooks;
}

// computing_ is set with the submission, under the lock that Finish needs;
// if TrySubmit throws, nothing was submitted.
grpc::Status InspectReactor::SubmitComputeLocked() {
  service_->metrics()->CallStarted();
  admitted_ = true;
  computing_ = service_->pool().TrySubmit([this] { Compute(); });
  if (!computing_)
    return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                        "server busy: too many heavy calls admitted; retry with backoff");
  return grpc::Status::OK;
}

// ---- compute side ----

void InspectReactor::Compute() {
  const grpc::Status st = Guarded("Inspect", "Compute", [this] { return RunInspection(); });
  std::lock_guard<std::mutex> lock(mu_);
  computing_ = false;
  RequestFinishLocked(st);
  MaybeFinishLocked();
}

// Parse (done at the header) -> core (InspectPart) -> convert; sends the result.
grpc::Status InspectReactor::RunInspection() {
  const wire::InspectPart& part = reader_.part();
  std::shared_ptr<const MeshIndex> index = part_index_;
  if (!index)
    if (grpc::Status st = service_->ResolveMesh(ctx_, part.mesh, "part.part", &index); !st.ok())
      return st;
  auto progress = [this](InspectionStage stage, const std::string& view, std::size_t points) {
    SendProgress(wire::StageToProto(stage), view, points);
  };
  auto result = InspectPart(*index, part.world_from_part, std::move(reader_.views()), part.settings,
                            progress, &cancel_.flag());
  if (!result.ok()) return ToGrpc(result.status());
  v1::InspectResponse resp;
  wire::InspectionResultToProto(part.id, *result, part.settings.error_map, part.return_deviations,
                                resp.mutable_result());
  if (part.return_png) {
    auto png = ErrorMapPngBytes(result->merged.cloud_in_world, part.world_from_part,
                                result->error_map, index->mesh(), result->plan);
    if (!png.ok()) return ToGrpc(png.status());
    resp.mutable_result()->set_png(*std::move(png));
  }
  if (grpc::Status fits = service_->FitsOneMessage(resp, "Inspect result"); !fits.ok()) return fits;
  Send(std::move(resp));
  return grpc::Status::OK;
}

// ---- writing side and finish ----

// Once the call's status is decided, nothing more is queued.
void InspectReactor::Send(v1::InspectResponse msg) {
  std::lock_guard<std::mutex> lock(mu_);
  if (finish_requested_) return;
  out_.push_back(std::move(msg));
  if (!writing_) {
    writing_ = true;
    StartWrite(&out_.front());
  }
}

void InspectReactor::SendProgress(v1::Progress::Stage stage, const std::string& view,
                                  uint64_t points, const std::string& detail) {
  v1::InspectResponse msg;
  v1::Progress* p = msg.mutable_progress();
  p->set_stage(stage);
  p->set_view(view);
  p->set_points(points);
  p->set_detail(detail);
  Send(std::move(msg));
}

void InspectReactor::OnWriteDone(bool ok) {
  std::lock_guard<std::mutex> lock(mu_);
  const grpc::Status st = Guarded("Inspect", "OnWriteDone", [&] { StartNextWriteLocked(ok); });
  if (!st.ok()) {  // StartWrite is the step's last call, so no write is in flight
    out_.clear();
    writing_ = false;
    RequestFinishLocked(st);
  }
  MaybeFinishLocked();
}

void InspectReactor::StartNextWriteLocked(bool ok) {
  out_.pop_front();
  if (!ok) out_.clear();  // the client is gone; nothing more will be delivered
  if (out_.empty()) {
    writing_ = false;
    return;
  }
  StartWrite(&out_.front());
}

void InspectReactor::RequestFinish(const grpc::Status& st) {
  std::lock_guard<std::mutex> lock(mu_);
  RequestFinishLocked(st);
  MaybeFinishLocked();
}

// The first status requested is the call's.
void InspectReactor::RequestFinishLocked(const grpc::Status& st) {
  if (finish_requested_) return;
  finish_requested_ = true;
  final_status_ = st;
}

// Finish once everything that uses the reactor is done: no write in flight
// and no pool job running (OnDone deletes the reactor right after Finish).
// If logging the call throws, the call ends with that status instead.
void InspectReactor::MaybeFinishLocked() {
  if (finished_ || !finish_requested_ || writing_ || computing_) return;
  finished_ = true;
  const grpc::Status logged = Guarded("Inspect", "Finish", [this] { LogAndCountLocked(); });
  if (admitted_) service_->metrics()->CallEnded();
  Finish(logged.ok() ? final_status_ : logged);
}

void InspectReactor::LogAndCountLocked() {
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  service_->LogCall(request_id_, "Inspect", ctx_->peer(), reader_.total_points(), final_status_,
                    seconds, cancel_.MillisecondsSinceRaised());
  service_->metrics()->RecordRpc("Inspect", CodeName(final_status_.error_code()), seconds);
  if (final_status_.ok()) service_->metrics()->AddPoints(reader_.total_points());
}

}  // namespace surfinspect::server
