#include "server/inspection_service.h"

#include <openssl/crypto.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"
#include "core/filter/link_clustering.h"
#include "core/io/mesh_hash.h"
#include "core/pipeline/inspection.h"
#include "core/registration/calibration.h"
#include "core/registration/registration.h"
#include "core/report/error_map_png.h"
#include "core/types/cancel.h"
#include "core/types/transform.h"
#include "server/cancel_signal.h"
#include "server/guarded.h"
#include "server/status_mapping.h"

namespace surfinspect::server {
namespace {

using Clock = std::chrono::steady_clock;

// One reactor per unary heavy call. The work runs on the pool; Finish is
// the last thing it touches, because OnDone (which deletes the reactor) may
// run as soon as Finish is called. Start, Run and Done run under Guarded
// (server/guarded.h): an exception ends the call with its status.
class HeavyCall final : public grpc::ServerUnaryReactor {
 public:
  using Work = std::function<grpc::Status(const std::atomic<bool>& cancel)>;
  HeavyCall(InspectionService* service, grpc::CallbackServerContext* ctx, const char* method,
            uint64_t points, Work work)
      : service_(service),
        ctx_(ctx),
        method_(method),
        points_(points),
        work_(std::move(work)),
        request_id_(service->RequestId(ctx)),
        start_(Clock::now()) {}

  void Start() {
    const grpc::Status st = Guarded(method_, "Start", [this] { return Admit(); });
    if (!st.ok()) Done(st);
  }
  void OnCancel() override { cancel_.Raise(); }
  void OnDone() override { delete this; }

 private:
  // OK once the work is on the pool; submitting is the last step, so an
  // exception before it leaves nothing running.
  grpc::Status Admit() {
    if (grpc::Status auth = service_->Authorize(ctx_); !auth.ok()) return auth;
    if (grpc::Status room =
            service_->Reserve(points_ * UnaryCloudBytesPerPoint(), method_, &reservation_);
        !room.ok())
      return room;
    service_->metrics()->CallStarted();
    admitted_ = true;
    if (!service_->pool().TrySubmit([this] { Run(); }))
      return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                          absl::StrCat("server busy: ", service_->config().max_admitted_calls,
                                       " heavy calls already admitted; retry with backoff"));
    return grpc::Status::OK;
  }
  void Run() {
    const grpc::Status st = Guarded(method_, "Run", [this] {
      return cancel_.raised() ? grpc::Status(grpc::StatusCode::CANCELLED, "cancelled before start")
                              : work_(cancel_.flag());
    });
    Done(st);
  }
  // If logging the call throws, the call ends with that status instead.
  void Done(const grpc::Status& st) {
    const grpc::Status logged = Guarded(method_, "Done", [&] { LogAndCount(st); });
    if (admitted_) service_->metrics()->CallEnded();
    Finish(logged.ok() ? st : logged);
  }
  void LogAndCount(const grpc::Status& st) {
    const double seconds = std::chrono::duration<double>(Clock::now() - start_).count();
    service_->LogCall(request_id_, method_, ctx_->peer(), points_, st, seconds,
                      cancel_.MillisecondsSinceRaised());
    service_->metrics()->RecordRpc(method_, CodeName(st.error_code()), seconds);
    if (st.ok()) service_->metrics()->AddPoints(points_);
  }

  // First member, so it is released last: after the call's own data.
  MemoryBudget::Reservation reservation_;
  InspectionService* service_;
  grpc::CallbackServerContext* ctx_;
  const char* method_;
  uint64_t points_;
  Work work_;
  std::string request_id_;
  Clock::time_point start_;
  bool admitted_ = false;
  CancelSignal cancel_;
};

grpc::Status FromCore(const absl::Status& st) { return ToGrpc(st); }

// The steps around the core calls (a cloud's conversion, the plan, the
// response) do not poll; the work checks IsCancelled between them, so a call
// cancelled there ends before the next step instead of finishing it.
grpc::Status CancelledBetweenSteps() {
  return grpc::Status(grpc::StatusCode::CANCELLED, "cancelled between steps");
}

}  // namespace

InspectionService::InspectionService(ServiceConfig config, Metrics* metrics)
    : config_(std::move(config)),
      metrics_(metrics),
      mesh_cache_(config_.mesh_cache_bytes),
      budget_(config_.memory_budget_bytes != 0 ? config_.memory_budget_bytes : UINT64_MAX),
      pool_(config_.threads, config_.max_admitted_calls) {
  metrics_->SetMemoryBudget(budget_.budget_bytes());
  budget_.SetObserver([metrics = metrics_](uint64_t reserved, uint64_t refused) {
    metrics->SetMemoryReserved(reserved, refused);
  });
}

InspectionService::~InspectionService() = default;

grpc::Status InspectionService::Reserve(uint64_t bytes, const std::string& what,
                                        MemoryBudget::Reservation* reservation) {
  auto r = budget_.TryReserve(bytes, what);
  if (!r.ok()) return ToGrpc(r.status());
  *reservation = *std::move(r);
  return grpc::Status::OK;
}

grpc::Status InspectionService::FitsOneMessage(const google::protobuf::MessageLite& response,
                                               const char* what) const {
  const uint64_t bytes = response.ByteSizeLong();
  if (bytes <= config_.max_message_bytes) return grpc::Status::OK;
  return grpc::Status(
      grpc::StatusCode::FAILED_PRECONDITION,
      absl::StrCat("RESPONSE_TOO_LARGE: the ", what, " is ", (bytes + (1 << 20) - 1) >> 20,
                   " MiB, over the server's message limit of ", config_.max_message_bytes >> 20,
                   " MiB; ask for less (fewer points, no deviations or PNG) or raise "
                   "--max-message-mb on the server and the client"));
}

grpc::Status InspectionService::Authorize(const grpc::CallbackServerContext* ctx) const {
  if (config_.auth_token.empty()) return grpc::Status::OK;
  const auto& md = ctx->client_metadata();
  auto it = md.find("authorization");
  const std::string expected = "Bearer " + config_.auth_token;
  if (it == md.end())
    return grpc::Status(grpc::StatusCode::UNAUTHENTICATED, "missing authorization: Bearer token");
  const std::string got(it->second.data(), it->second.size());
  // Constant-time comparison: no timing oracle on the token.
  if (got.size() != expected.size() || CRYPTO_memcmp(got.data(), expected.data(), got.size()) != 0)
    return grpc::Status(grpc::StatusCode::UNAUTHENTICATED, "bad bearer token");
  return grpc::Status::OK;
}

grpc::Status InspectionService::ResolveMesh(grpc::CallbackServerContext* ctx,
                                            const v1::MeshRef& ref, const std::string& field,
                                            std::shared_ptr<const MeshIndex>* out) {
  if (ref.has_inline_()) {
    const std::string hash = MeshSha256(ref.inline_().vertices(), ref.inline_().triangles());
    if ((*out = mesh_cache_.Find(hash))) {
      metrics_->MeshCacheHit();
      return grpc::Status::OK;
    }
    metrics_->MeshCacheMiss();
    MemoryBudget::Reservation building;
    const uint64_t triangles = ref.inline_().triangles().size() / 12;
    if (grpc::Status room =
            Reserve(triangles * MeshIndexBytesPerTriangle(), field + " mesh index", &building);
        !room.ok())
      return room;
    auto mesh = wire::MeshFromProto(ref.inline_(), field + ".inline", config_.limits);
    if (!mesh.ok()) return FromCore(mesh.status());
    auto index = MeshIndex::Build(*std::move(mesh));
    if (!index.ok()) return FromCore(index.status());
    std::shared_ptr<const MeshIndex> shared(std::move(*index));
    mesh_cache_.Insert(hash, shared);
    *out = std::move(shared);
    return grpc::Status::OK;
  }
  if (ref.source_case() == v1::MeshRef::kSha256) {
    if ((*out = mesh_cache_.Find(ref.sha256()))) {
      metrics_->MeshCacheHit();
      return grpc::Status::OK;
    }
    metrics_->MeshCacheMiss();
    ctx->AddTrailingMetadata("surfinspect-reason", "MESH_NOT_CACHED");
    return grpc::Status(grpc::StatusCode::FAILED_PRECONDITION,
                        absl::StrCat("MESH_NOT_CACHED: ", field, ".sha256 ", ref.sha256(),
                                     " is not cached on this replica; send the mesh inline"));
  }
  return InvalidField(field, "mesh is missing (set inline or sha256)");
}

std::string InspectionService::RequestId(const grpc::CallbackServerContext* ctx) {
  auto it = ctx->client_metadata().find("x-request-id");
  if (it != ctx->client_metadata().end() && it->second.size() <= 128)
    return std::string(it->second.data(), it->second.size());
  return absl::StrCat("r", next_request_.fetch_add(1));
}

void InspectionService::LogCall(const std::string& request_id, const std::string& method,
                                const std::string& peer, uint64_t points,
                                const grpc::Status& status, double seconds, double stop_ms) {
  if (config_.json_logs) {
    // spdlog does not escape JSON; nlohmann does.
    nlohmann::json line = {{"event", "rpc"},
                           {"request_id", request_id},
                           {"method", method},
                           {"peer", peer},
                           {"points", points},
                           {"code", CodeName(status.error_code())},
                           {"message", status.error_message()},
                           {"seconds", seconds}};
    if (!std::isnan(stop_ms)) line["stopped_after_cancel_ms"] = stop_ms;
    spdlog::info("{}", line.dump());
    return;
  }
  const std::string stopped =
      std::isnan(stop_ms) ? ""
                          : fmt::format(", work stopped {:.1f} ms after the cancellation", stop_ms);
  if (status.ok())
    spdlog::info("[{}] {} from {}: OK, {} points, {:.3f} s{}", request_id, method, peer, points,
                 seconds, stopped);
  else
    spdlog::warn("[{}] {} from {}: {} ({}), {} points, {:.3f} s{}", request_id, method, peer,
                 CodeName(status.error_code()), status.error_message(), points, seconds, stopped);
}

grpc::ServerUnaryReactor* InspectionService::RunHeavy(grpc::CallbackServerContext* ctx,
                                                      const char* method, uint64_t points,
                                                      Work work) {
  HeavyCall* call = nullptr;
  const grpc::Status st = Guarded(
      method, "Accept", [&] { call = new HeavyCall(this, ctx, method, points, std::move(work)); });
  if (!st.ok()) {  // no reactor of our own: the context's default one reports the status
    grpc::ServerUnaryReactor* fallback = ctx->DefaultReactor();
    fallback->Finish(st);
    return fallback;
  }
  call->Start();
  return call;
}

grpc::ServerUnaryReactor* InspectionService::Filter(grpc::CallbackServerContext* ctx,
                                                    const v1::FilterRequest* req,
                                                    v1::FilterResponse* resp) {
  const uint64_t points = uint64_t{req->cloud().width()} * req->cloud().height();
  return RunHeavy(ctx, "Filter", points, [this, req, resp](const std::atomic<bool>& cancel) {
    auto cloud = wire::CloudFromProto(req->cloud(), "cloud", config_.limits);
    if (!cloud.ok()) return FromCore(cloud.status());
    auto settings = wire::FilterSettingsFromProto(req->settings(), "settings");
    if (!settings.ok()) return FromCore(settings.status());
    LinkClusteringResult clusters;
    if (auto st = RemoveOutliers(*cloud, *settings, clusters, &cancel); !st.ok())
      return FromCore(st);
    if (IsCancelled(&cancel)) return CancelledBetweenSteps();
    wire::FilterResultToProto(*cloud, clusters, resp);
    return FitsOneMessage(*resp, "Filter response");
  });
}

grpc::ServerUnaryReactor* InspectionService::Calibrate(grpc::CallbackServerContext* ctx,
                                                       const v1::CalibrateRequest* req,
                                                       v1::CalibrateResponse* resp) {
  const uint64_t points = uint64_t{req->scan().width()} * req->scan().height();
  return RunHeavy(
      ctx, "Calibrate", points, [this, ctx, req, resp](const std::atomic<bool>& cancel) {
        auto world_from_gauge =
            wire::TransformFromProto(req->world_from_gauge(), "world_from_gauge");
        if (!world_from_gauge.ok()) return FromCore(world_from_gauge.status());
        auto initial =
            wire::TransformFromProto(req->initial_world_from_sensor(), "initial_world_from_sensor");
        if (!initial.ok()) return FromCore(initial.status());
        auto scan = wire::CloudFromProto(req->scan(), "scan", config_.limits);
        if (!scan.ok()) return FromCore(scan.status());
        CalibrationSettings settings;
        settings.filter_outliers = !req->skip_filter();
        auto filter = wire::FilterSettingsFromProto(req->filter(), "filter");
        if (!filter.ok()) return FromCore(filter.status());
        settings.filter = *filter;
        auto icp = wire::IcpSettingsFromProto(req->icp(), "icp");
        if (!icp.ok()) return FromCore(icp.status());
        settings.icp = *icp;
        std::shared_ptr<const MeshIndex> gauge;
        if (grpc::Status st = ResolveMesh(ctx, req->gauge(), "gauge", &gauge); !st.ok()) return st;
        auto cal =
            CalibrateViewpoint(*gauge, *world_from_gauge, *scan, *initial, settings, &cancel);
        if (!cal.ok()) return FromCore(cal.status());
        wire::CalibrationToProto(*cal, resp);
        return FitsOneMessage(*resp, "Calibrate response");
      });
}

grpc::ServerUnaryReactor* InspectionService::Register(grpc::CallbackServerContext* ctx,
                                                      const v1::RegisterRequest* req,
                                                      v1::RegisterResponse* resp) {
  uint64_t points = 0;
  for (const auto& v : req->views()) points += uint64_t{v.cloud().width()} * v.cloud().height();
  return RunHeavy(
      ctx, "Register", points, [this, ctx, req, resp, points](const std::atomic<bool>& cancel) {
        if (req->views().empty()) return InvalidField("views", "at least one view is required");
        if (points > config_.limits.max_points)
          return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                              absl::StrCat("views: ", points, " points exceed the limit of ",
                                           config_.limits.max_points));
        auto filter = wire::FilterSettingsFromProto(req->filter_settings(), "filter_settings");
        if (!filter.ok()) return FromCore(filter.status());
        std::vector<ViewScan> views;
        for (int i = 0; i < req->views_size(); ++i) {
          const std::string field = absl::StrCat("views[", i, "]");
          const v1::ViewScan& v = req->views(i);
          auto pose = wire::TransformFromProto(v.world_from_sensor(), field + ".world_from_sensor");
          if (!pose.ok()) return FromCore(pose.status());
          auto cloud = wire::CloudFromProto(v.cloud(), field + ".cloud", config_.limits);
          if (!cloud.ok()) return FromCore(cloud.status());
          views.push_back(
              {v.name().empty() ? absl::StrCat("view", i) : v.name(), *std::move(cloud), *pose});
        }
        if (req->filter())
          if (auto st = FilterViews(views, *filter, &cancel); !st.ok()) return FromCore(st);
        auto merged = RegisterToWorld(views, &cancel);
        if (!merged.ok()) return FromCore(merged.status());
        if (req->best_fit()) {
          auto world_from_part =
              wire::TransformFromProto(req->world_from_part(), "world_from_part");
          if (!world_from_part.ok()) return FromCore(world_from_part.status());
          std::shared_ptr<const MeshIndex> part;
          if (grpc::Status st = ResolveMesh(ctx, req->part(), "part", &part); !st.ok()) return st;
          auto fit =
              BestFitToCad(*part, *world_from_part, *merged, DefaultBestFitSettings(), &cancel);
          if (!fit.ok()) return FromCore(fit.status());
          merged->cloud_in_world = TransformCloud(merged->cloud_in_world, fit->correction);
          wire::TransformToProto(fit->correction, resp->mutable_best_fit_correction());
        }
        if (IsCancelled(&cancel)) return CancelledBetweenSteps();
        wire::MergedCloudToProto(*merged, resp);
        return FitsOneMessage(*resp, "Register response");
      });
}

grpc::ServerUnaryReactor* InspectionService::ErrorMap(grpc::CallbackServerContext* ctx,
                                                      const v1::ErrorMapRequest* req,
                                                      v1::ErrorMapResponse* resp) {
  const uint64_t points = uint64_t{req->cloud().width()} * req->cloud().height();
  return RunHeavy(ctx, "ErrorMap", points, [this, ctx, req, resp](const std::atomic<bool>& cancel) {
    auto cloud = wire::CloudFromProto(req->cloud(), "cloud", config_.limits);
    if (!cloud.ok()) return FromCore(cloud.status());
    auto world_from_part = wire::TransformFromProto(req->world_from_part(), "world_from_part");
    if (!world_from_part.ok()) return FromCore(world_from_part.status());
    auto settings = wire::ErrorMapSettingsFromProto(req->settings(), "settings");
    if (!settings.ok()) return FromCore(settings.status());
    auto plan = req->has_plan() ? wire::PlanFromProto(req->plan(), *settings, "plan")
                                : absl::StatusOr<InspectionPlan>(PlanFromSettings(*settings));
    if (!plan.ok()) return FromCore(plan.status());
    std::shared_ptr<const MeshIndex> part;
    if (grpc::Status st = ResolveMesh(ctx, req->part(), "part", &part); !st.ok()) return st;
    if (auto st = ValidateInspectionPlan(*plan, part->mesh(), {}, "plan"); !st.ok())
      return FromCore(st);
    auto map = ComputeErrorMap(*part, *cloud, *world_from_part, *settings, &cancel);
    if (!map.ok()) return FromCore(map.status());
    auto outcome = EvaluatePlan(*map, *cloud, part->mesh(), *plan, settings->threads, &cancel);
    if (!outcome.ok()) return FromCore(outcome.status());
    if (IsCancelled(&cancel)) return CancelledBetweenSteps();
    wire::ErrorMapToProto(*map, *settings, *outcome, req->return_deviations(), resp);
    if (req->return_png()) {
      auto png = ErrorMapPngBytes(*cloud, *world_from_part, *map, part->mesh(), *outcome);
      if (!png.ok()) return FromCore(png.status());
      resp->set_png(*std::move(png));
    }
    return FitsOneMessage(*resp, "ErrorMap response");
  });
}

}  // namespace surfinspect::server
