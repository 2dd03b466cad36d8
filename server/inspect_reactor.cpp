#include "server/inspect_reactor.h"

#include "absl/strings/str_cat.h"
#include "core/pipeline/inspection.h"
#include "server/status_mapping.h"

namespace surfinspect::server {

InspectReactor::InspectReactor(InspectionService* service, grpc::CallbackServerContext* ctx)
    : service_(service),
      ctx_(ctx),
      request_id_(service->RequestId(ctx)),
      start_(std::chrono::steady_clock::now()) {
  if (grpc::Status auth = service_->Authorize(ctx_); !auth.ok()) {
    RequestFinish(auth);
    return;
  }
  StartRead(&in_);
}

grpc::ServerBidiReactor<v1::InspectRequest, v1::InspectResponse>* InspectionService::Inspect(
    grpc::CallbackServerContext* ctx) {
  return new InspectReactor(this, ctx);
}

grpc::Status InspectReactor::Consume(const v1::InspectRequest& msg) {
  const wire::Limits& limits = service_->config().limits;
  switch (msg.message_case()) {
    case v1::InspectRequest::kPart: {
      if (state_ != State::kExpectPart)
        return InvalidField("part", "only one part header per stream");
      header_ = msg.part();
      if (header_.part_id().empty() || header_.part_id().size() > 256)
        return InvalidField("part.part_id", "must be 1..256 characters");
      if (header_.part().source_case() == v1::MeshRef::SOURCE_NOT_SET)
        return InvalidField("part.part", "mesh is missing (set inline or sha256)");
      // A mesh sent by hash is looked up now, so a miss fails before the
      // client streams its views; an inline mesh is indexed on the pool.
      if (header_.part().source_case() == v1::MeshRef::kSha256)
        if (grpc::Status st = service_->ResolveMesh(ctx_, header_.part(), "part.part", &part_);
            !st.ok())
          return st;
      if (auto t = wire::TransformFromProto(header_.world_from_part(), "part.world_from_part");
          !t.ok())
        return ToGrpc(t.status());
      if (auto s = wire::ErrorMapSettingsFromProto(header_.error_map(), "part.error_map"); !s.ok())
        return ToGrpc(s.status());
      if (auto f = wire::FilterSettingsFromProto(header_.filter(), "part.filter",
                                                 LinkClusteringSettings::ForInspection());
          !f.ok())
        return ToGrpc(f.status());
      state_ = State::kExpectView;
      return grpc::Status::OK;
    }
    case v1::InspectRequest::kView: {
      if (state_ == State::kExpectPart)
        return InvalidField("view", "the part header must come first");
      if (state_ == State::kInView)
        return InvalidField("view", absl::StrCat("view '", views_.empty() ? "" : "previous",
                                                 "' is incomplete: ", view_cloud_.received_bytes(),
                                                 " of ", view_cloud_.expected_bytes(), " bytes"));
      const v1::ViewHeader& v = msg.view();
      const std::string field = absl::StrCat("view[", views_.size(), "]");
      if (auto st = wire::CheckCloudShape(v.width(), v.height(), field, limits); !st.ok())
        return ToGrpc(st);
      total_points_ += uint64_t{v.width()} * v.height();
      if (total_points_ > limits.max_points)
        return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                            absl::StrCat("part: ", total_points_, " points exceed the limit of ",
                                         limits.max_points));
      auto pose = wire::TransformFromProto(v.world_from_sensor(), field + ".world_from_sensor");
      if (!pose.ok()) return ToGrpc(pose.status());
      ViewScan scan;
      scan.name = v.name().empty() ? absl::StrCat("view", views_.size()) : v.name();
      scan.world_from_sensor = *pose;
      views_.push_back(std::move(scan));
      view_cloud_.Start(v.width(), v.height());
      state_ = State::kInView;
      return grpc::Status::OK;
    }
    case v1::InspectRequest::kChunk: {
      if (state_ != State::kInView)
        return InvalidField("chunk", "a chunk must follow a view header");
      const std::string field = absl::StrCat("view '", views_.back().name, "'");
      if (auto st = view_cloud_.Add(msg.chunk().xyz(), field); !st.ok()) return ToGrpc(st);
      if (view_cloud_.complete()) {
        auto cloud = view_cloud_.Take(field);
        if (!cloud.ok()) return ToGrpc(cloud.status());
        views_.back().cloud_in_sensor = *std::move(cloud);
        state_ = State::kExpectView;
        SendProgress(v1::Progress::STAGE_VIEW_RECEIVED, views_.back().name,
                     views_.back().cloud_in_sensor.size());
      }
      return grpc::Status::OK;
    }
    case v1::InspectRequest::kEnd: {
      if (state_ == State::kInView)
        return InvalidField("end", absl::StrCat("view '", views_.back().name,
                                                "' is incomplete: ", view_cloud_.received_bytes(),
                                                " of ", view_cloud_.expected_bytes(), " bytes"));
      if (state_ != State::kExpectView || views_.empty())
        return InvalidField("end", "a part header and at least one view must come first");
      state_ = State::kEnded;
      return grpc::Status::OK;
    }
    default:
      return InvalidField("message", "empty InspectRequest");
  }
}

void InspectReactor::OnReadDone(bool ok) {
  if (!ok) {  // the client closed its side (or the call died) before the end marker
    RequestFinish(
        grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, "stream closed before EndOfPart"));
    return;
  }
  if (grpc::Status st = Consume(in_); !st.ok()) {
    RequestFinish(st);
    return;
  }
  if (state_ != State::kEnded) {
    StartRead(&in_);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mu_);
    computing_ = true;
  }
  service_->metrics()->CallStarted();
  admitted_ = true;
  if (!service_->pool().TrySubmit([this] { Compute(); })) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      computing_ = false;
    }
    RequestFinish(grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                               "server busy: too many heavy calls admitted; retry with backoff"));
  }
}

void InspectReactor::Compute() {
  grpc::Status st;
  try {
    std::shared_ptr<const MeshIndex> part = part_;
    if (!part) st = service_->ResolveMesh(ctx_, header_.part(), "part.part", &part);
    if (st.ok()) {
      InspectionSettings settings;
      settings.filter = !header_.skip_filter();
      settings.filter_settings = *wire::FilterSettingsFromProto(
          header_.filter(), "part.filter", LinkClusteringSettings::ForInspection());
      settings.error_map = *wire::ErrorMapSettingsFromProto(header_.error_map(), "part.error_map");
      const Eigen::Isometry3d world_from_part =
          *wire::TransformFromProto(header_.world_from_part(), "part.world_from_part");
      auto progress = [this](InspectionStage stage, const std::string& view, std::size_t points) {
        const v1::Progress::Stage s =
            stage == InspectionStage::kViewFiltered     ? v1::Progress::STAGE_VIEW_FILTERED
            : stage == InspectionStage::kViewRegistered ? v1::Progress::STAGE_VIEW_REGISTERED
                                                        : v1::Progress::STAGE_ERROR_MAP;
        SendProgress(s, view, points);
      };
      auto result = InspectPart(*part, world_from_part, std::move(views_), settings, progress,
                                &cancel_.flag());
      if (!result.ok()) {
        st = ToGrpc(result.status());
      } else {
        v1::InspectResponse resp;
        v1::InspectResult* r = resp.mutable_result();
        r->set_part_id(header_.part_id());
        r->set_verdict(result->error_map.verdict.pass ? "pass" : "fail");
        r->set_report_json(ErrorMapReportText(result->error_map, settings.error_map));
        for (const auto& v : result->views) {
          v1::ViewSummary* s = r->add_views();
          s->set_name(v.name);
          s->set_valid_points(v.valid_points);
          s->set_removed_points(v.removed_points);
        }
        if (header_.return_deviations()) {
          r->set_deviations(wire::PackFloats(result->error_map.deviation_mm));
          wire::CloudToProto(result->merged.cloud_in_world, r->mutable_merged());
        }
        if (header_.return_png()) {
          auto png = ErrorMapPngBytes(result->merged.cloud_in_world, world_from_part,
                                      result->error_map, part->mesh());
          if (png.ok())
            r->set_png(*std::move(png));
          else
            st = ToGrpc(png.status());
        }
        if (st.ok()) Send(std::move(resp));
      }
    }
  } catch (const std::exception& e) {
    st = grpc::Status(grpc::StatusCode::INTERNAL, absl::StrCat("internal error: ", e.what()));
  }
  std::lock_guard<std::mutex> lock(mu_);
  computing_ = false;
  if (!finish_requested_) {
    finish_requested_ = true;
    final_status_ = st;
  }
  MaybeFinishLocked();
}

void InspectReactor::Send(v1::InspectResponse msg) {
  std::lock_guard<std::mutex> lock(mu_);
  if (finished_) return;
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
  out_.pop_front();
  if (!ok) out_.clear();  // the client is gone; nothing more will be delivered
  if (!out_.empty()) {
    StartWrite(&out_.front());
  } else {
    writing_ = false;
    MaybeFinishLocked();
  }
}

void InspectReactor::RequestFinish(const grpc::Status& st) {
  std::lock_guard<std::mutex> lock(mu_);
  if (!finish_requested_) {
    finish_requested_ = true;
    final_status_ = st;
  }
  MaybeFinishLocked();
}

// Finish once everything that uses the reactor is done: no write in flight
// and no pool job running (OnDone deletes the reactor right after Finish).
void InspectReactor::MaybeFinishLocked() {
  if (finished_ || !finish_requested_ || writing_ || computing_) return;
  finished_ = true;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  service_->LogCall(request_id_, "Inspect", ctx_->peer(), total_points_, final_status_, seconds,
                    cancel_.MillisecondsSinceRaised());
  service_->metrics()->RecordRpc("Inspect", CodeName(final_status_.error_code()), seconds);
  if (final_status_.ok()) service_->metrics()->AddPoints(total_points_);
  if (admitted_) service_->metrics()->CallEnded();
  Finish(final_status_);
}

}  // namespace surfinspect::server
