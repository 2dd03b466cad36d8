#include "server/inspect_reactor.h"

#include "absl/strings/str_cat.h"
#include "server/guarded.h"
#include "server/status_mapping.h"

namespace surfinspect::server {

InspectReactor::InspectReactor(InspectionService* service, grpc::CallbackServerContext* ctx)
    : service_(service),
      ctx_(ctx),
      request_id_(service->RequestId(ctx)),
      start_(std::chrono::steady_clock::now()) {}

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
  if (state_ != State::kEnded) {
    StartRead(&in_);
    return grpc::Status::OK;
  }
  return SubmitComputeLocked();
}

grpc::Status InspectReactor::Consume(v1::InspectRequest* msg) {
  switch (msg->message_case()) {
    case v1::InspectRequest::kPart:
      return ConsumePart(msg->mutable_part());
    case v1::InspectRequest::kView:
      return ConsumeView(msg->view());
    case v1::InspectRequest::kChunk:
      return ConsumeChunk(msg->chunk());
    case v1::InspectRequest::kEnd:
      return ConsumeEnd();
    default:
      return InvalidField("message", "empty InspectRequest");
  }
}

// Validates and parses the header into part_. The mesh moves out of the read
// buffer, which the next read overwrites anyway.
grpc::Status InspectReactor::ConsumePart(v1::PartHeader* header) {
  if (state_ != State::kExpectPart) return InvalidField("part", "only one part header per stream");
  if (header->part_id().empty() || header->part_id().size() > 256)
    return InvalidField("part.part_id", "must be 1..256 characters");
  if (header->part().source_case() == v1::MeshRef::SOURCE_NOT_SET)
    return InvalidField("part.part", "mesh is missing (set inline or sha256)");
  // A mesh sent by hash is looked up now, so a miss fails before the client
  // streams its views; an inline mesh is indexed on the pool.
  if (header->part().source_case() == v1::MeshRef::kSha256)
    if (grpc::Status st = service_->ResolveMesh(ctx_, header->part(), "part.part", &part_.index);
        !st.ok())
      return st;
  auto world_from_part =
      wire::TransformFromProto(header->world_from_part(), "part.world_from_part");
  if (!world_from_part.ok()) return ToGrpc(world_from_part.status());
  auto error_map = wire::ErrorMapSettingsFromProto(header->error_map(), "part.error_map");
  if (!error_map.ok()) return ToGrpc(error_map.status());
  auto filter = wire::FilterSettingsFromProto(header->filter(), "part.filter",
                                              LinkClusteringSettings::ForInspection());
  if (!filter.ok()) return ToGrpc(filter.status());
  // The plan's values are checked against the mesh here when it came by
  // hash, else by InspectPart once the inline mesh is indexed.
  if (header->has_plan()) {
    auto plan = wire::PlanFromProto(header->plan(), *error_map, "part.plan");
    if (!plan.ok()) return ToGrpc(plan.status());
    if (part_.index)
      if (auto st = ValidateInspectionPlan(*plan, part_.index->mesh(), {}, "part.plan"); !st.ok())
        return ToGrpc(st);
    part_.settings.plan = *std::move(plan);
  }
  part_.id = header->part_id();
  part_.mesh.Swap(header->mutable_part());
  part_.world_from_part = *world_from_part;
  part_.settings.filter = !header->skip_filter();
  part_.settings.filter_settings = *filter;
  part_.settings.error_map = *error_map;
  part_.return_deviations = header->return_deviations();
  part_.return_png = header->return_png();
  state_ = State::kExpectView;
  return grpc::Status::OK;
}

grpc::Status InspectReactor::ConsumeView(const v1::ViewHeader& view) {
  const wire::Limits& limits = service_->config().limits;
  if (state_ == State::kExpectPart) return InvalidField("view", "the part header must come first");
  if (state_ == State::kInView) return IncompleteView("view", views_.empty() ? "" : "previous");
  const std::string field = absl::StrCat("view[", views_.size(), "]");
  if (auto st = wire::CheckCloudShape(view.width(), view.height(), field, limits); !st.ok())
    return ToGrpc(st);
  total_points_ += uint64_t{view.width()} * view.height();
  if (total_points_ > limits.max_points)
    return grpc::Status(
        grpc::StatusCode::RESOURCE_EXHAUSTED,
        absl::StrCat("part: ", total_points_, " points exceed the limit of ", limits.max_points));
  auto pose = wire::TransformFromProto(view.world_from_sensor(), field + ".world_from_sensor");
  if (!pose.ok()) return ToGrpc(pose.status());
  ViewScan scan;
  scan.name = view.name().empty() ? absl::StrCat("view", views_.size()) : view.name();
  // Before a byte of the view is buffered: a part that does not fit is
  // refused now, while the client still holds its data to send again.
  const uint64_t view_points = uint64_t{view.width()} * view.height();
  if (grpc::Status room =
          service_->Reserve(view_points * InspectBytesPerPoint(),
                            absl::StrCat("Inspect part '", part_.id, "' view '", scan.name, "'"),
                            &reserved_.emplace_back());
      !room.ok())
    return room;
  scan.world_from_sensor = *pose;
  views_.push_back(std::move(scan));
  view_cloud_.Start(view.width(), view.height());
  state_ = State::kInView;
  return grpc::Status::OK;
}

grpc::Status InspectReactor::ConsumeChunk(const v1::CloudChunk& chunk) {
  if (state_ != State::kInView) return InvalidField("chunk", "a chunk must follow a view header");
  const std::string field = absl::StrCat("view '", views_.back().name, "'");
  if (auto st = view_cloud_.Add(chunk.xyz(), field); !st.ok()) return ToGrpc(st);
  if (!view_cloud_.complete()) return grpc::Status::OK;
  auto cloud = view_cloud_.Take(field);
  if (!cloud.ok()) return ToGrpc(cloud.status());
  views_.back().cloud_in_sensor = *std::move(cloud);
  state_ = State::kExpectView;
  SendProgress(v1::Progress::STAGE_VIEW_RECEIVED, views_.back().name,
               views_.back().cloud_in_sensor.size());
  return grpc::Status::OK;
}

grpc::Status InspectReactor::ConsumeEnd() {
  if (state_ == State::kInView) return IncompleteView("end", views_.back().name);
  if (state_ != State::kExpectView || views_.empty())
    return InvalidField("end", "a part header and at least one view must come first");
  state_ = State::kEnded;
  return grpc::Status::OK;
}

grpc::Status InspectReactor::IncompleteView(const std::string& field,
                                            const std::string& name) const {
  return InvalidField(
      field, absl::StrCat("view '", name, "' is incomplete: ", view_cloud_.received_bytes(), " of ",
                          view_cloud_.expected_bytes(), " bytes"));
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
  std::shared_ptr<const MeshIndex> index = part_.index;
  if (!index)
    if (grpc::Status st = service_->ResolveMesh(ctx_, part_.mesh, "part.part", &index); !st.ok())
      return st;
  auto progress = [this](InspectionStage stage, const std::string& view, std::size_t points) {
    SendProgress(wire::StageToProto(stage), view, points);
  };
  auto result = InspectPart(*index, part_.world_from_part, std::move(views_), part_.settings,
                            progress, &cancel_.flag());
  if (!result.ok()) return ToGrpc(result.status());
  v1::InspectResponse resp;
  wire::InspectionResultToProto(part_.id, *result, part_.settings.error_map,
                                part_.return_deviations, resp.mutable_result());
  if (part_.return_png) {
    auto png = ErrorMapPngBytes(result->merged.cloud_in_world, part_.world_from_part,
                                result->error_map, index->mesh(), result->plan);
    if (!png.ok()) return ToGrpc(png.status());
    resp.mutable_result()->set_png(*std::move(png));
  }
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
  service_->LogCall(request_id_, "Inspect", ctx_->peer(), total_points_, final_status_, seconds,
                    cancel_.MillisecondsSinceRaised());
  service_->metrics()->RecordRpc("Inspect", CodeName(final_status_.error_code()), seconds);
  if (final_status_.ok()) service_->metrics()->AddPoints(total_points_);
}

}  // namespace surfinspect::server
