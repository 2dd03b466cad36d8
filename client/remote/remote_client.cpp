#include "client/remote/remote_client.h"

#include <grpcpp/health_check_service_interface.h>

#include <chrono>
#include <thread>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "core/io/atomic_file.h"
#include "core/io/mesh_hash.h"
#include "core/types/status_macros.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "proto/convert.h"

namespace surfinspect::client {

absl::Status FromGrpc(const grpc::Status& s) {
  if (s.ok()) return absl::OkStatus();
  return absl::Status(static_cast<absl::StatusCode>(s.error_code()), s.error_message());
}

bool IsRetryable(const absl::Status& s) {
  return absl::IsUnavailable(s) || absl::IsResourceExhausted(s) || absl::IsDeadlineExceeded(s) ||
         absl::IsAborted(s);
}

bool IsMeshNotCached(const absl::Status& s) {
  return absl::IsFailedPrecondition(s) && absl::StartsWith(s.message(), "MESH_NOT_CACHED");
}

absl::StatusOr<std::unique_ptr<RemoteClient>> RemoteClient::Connect(const RemoteOptions& o) {
  if (o.target.empty()) return absl::InvalidArgumentError("--server: empty target");
  std::shared_ptr<grpc::ChannelCredentials> creds;
  if (o.tls_ca_file.empty()) {
    if (!o.tls_cert_file.empty())
      return absl::InvalidArgumentError("client certificate needs --tls-ca");
    creds = grpc::InsecureChannelCredentials();
  } else {
    grpc::SslCredentialsOptions ssl;
    ASSIGN_OR_RETURN(auto ca, ReadFileToString(o.tls_ca_file, 1 << 20));
    ssl.pem_root_certs = ca;
    if (!o.tls_cert_file.empty()) {
      ASSIGN_OR_RETURN(auto cert, ReadFileToString(o.tls_cert_file, 1 << 20));
      ASSIGN_OR_RETURN(auto key, ReadFileToString(o.tls_key_file, 1 << 20));
      ssl.pem_cert_chain = cert;
      ssl.pem_private_key = key;
    }
    creds = grpc::SslCredentials(ssl);
  }
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(1 << 30);
  args.SetMaxSendMessageSize(1 << 30);
  // Spread calls over every resolved address (headless services, lists).
  args.SetLoadBalancingPolicyName("round_robin");
  // A server that comes back (a restart, a late start) is found within 5 s
  // instead of gRPC's default of up to 120 s between connection attempts.
  args.SetInt(GRPC_ARG_MAX_RECONNECT_BACKOFF_MS, 5000);
  if (!o.tls_server_name.empty()) args.SetSslTargetNameOverride(o.tls_server_name);
  auto channel = grpc::CreateCustomChannel(o.target, creds, args);
  auto probe_channel = grpc::CreateCustomChannel(o.target, creds, args);
  return std::unique_ptr<RemoteClient>(
      new RemoteClient(o, std::move(channel), std::move(probe_channel)));
}

RemoteClient::RemoteClient(const RemoteOptions& o, std::shared_ptr<grpc::Channel> channel,
                           std::shared_ptr<grpc::Channel> probe_channel)
    : options_(o),
      channel_(std::move(channel)),
      probe_channel_(std::move(probe_channel)),
      stub_(v1::InspectionService::NewStub(channel_)) {}

void RemoteClient::Prepare(grpc::ClientContext* ctx) const {
  ctx->set_deadline(std::chrono::system_clock::now() +
                    std::chrono::milliseconds(static_cast<int64_t>(options_.timeout_s * 1000)));
  if (!options_.auth_token.empty())
    ctx->AddMetadata("authorization", "Bearer " + options_.auth_token);
  ctx->set_wait_for_ready(true);  // ride out a replica restarting
}

template <typename Request, typename Response>
absl::StatusOr<Response> RemoteClient::Unary(grpc::Status (v1::InspectionService::Stub::*rpc)(
                                                 grpc::ClientContext*, const Request&, Response*),
                                             const Request& request) {
  grpc::ClientContext ctx;
  Prepare(&ctx);
  Response response;
  RETURN_IF_ERROR(FromGrpc((stub_.get()->*rpc)(&ctx, request, &response)));
  return response;
}

absl::StatusOr<v1::FilterResponse> RemoteClient::Filter(const v1::FilterRequest& request) {
  return Unary(&v1::InspectionService::Stub::Filter, request);
}

namespace {

// A mesh that is small next to the rest of the call goes inline at once.
// Hash-first defeats round_robin: the inline retry after MESH_NOT_CACHED
// lands on the next replica, so with two replicas one of them answered
// MESH_NOT_CACHED to every call while the other did all the work (seen in
// tests/deploy/scale_out_test.py). Inline, every replica that serves a call
// caches the mesh; the hash still saves the bytes of meshes that are large.
bool SendMeshInline(const TriangleMesh& mesh, std::size_t other_bytes) {
  const std::size_t mesh_bytes = 12 * (mesh.vertices.size() + mesh.triangles.size());
  return mesh_bytes <= other_bytes / 8;
}

// Tries with the mesh's hash, then inline when the replica does not have it.
template <typename Req, typename Resp, typename Call>
absl::StatusOr<Resp> WithMesh(Req request, v1::MeshRef* (Req::*mutable_ref)(),
                              const TriangleMesh& mesh, Call call) {
  if (SendMeshInline(mesh, request.ByteSizeLong())) {
    wire::MeshToProto(mesh, (request.*mutable_ref)()->mutable_inline_());
    return call(request);
  }
  (request.*mutable_ref)()->set_sha256(MeshSha256(mesh));
  auto first = call(request);
  if (first.ok() || !IsMeshNotCached(first.status())) return first;
  wire::MeshToProto(mesh, (request.*mutable_ref)()->mutable_inline_());
  return call(request);
}

}  // namespace

absl::StatusOr<v1::CalibrateResponse> RemoteClient::Calibrate(v1::CalibrateRequest request,
                                                              const TriangleMesh& gauge) {
  return WithMesh<v1::CalibrateRequest, v1::CalibrateResponse>(
      std::move(request), &v1::CalibrateRequest::mutable_gauge, gauge,
      [this](const v1::CalibrateRequest& r) {
        return Unary(&v1::InspectionService::Stub::Calibrate, r);
      });
}

absl::StatusOr<v1::RegisterResponse> RemoteClient::Register(v1::RegisterRequest request,
                                                            const TriangleMesh* part) {
  auto call = [this](const v1::RegisterRequest& r) {
    return Unary(&v1::InspectionService::Stub::Register, r);
  };
  if (!part) return call(request);
  return WithMesh<v1::RegisterRequest, v1::RegisterResponse>(
      std::move(request), &v1::RegisterRequest::mutable_part, *part, call);
}

absl::StatusOr<v1::ErrorMapResponse> RemoteClient::ErrorMap(v1::ErrorMapRequest request,
                                                            const TriangleMesh& part) {
  return WithMesh<v1::ErrorMapRequest, v1::ErrorMapResponse>(
      std::move(request), &v1::ErrorMapRequest::mutable_part, part,
      [this](const v1::ErrorMapRequest& r) {
        return Unary(&v1::InspectionService::Stub::ErrorMap, r);
      });
}

absl::StatusOr<v1::InspectResult> RemoteClient::Inspect(v1::PartHeader header,
                                                        const TriangleMesh& part,
                                                        const std::vector<ViewScan>& views,
                                                        const ProgressFn& progress) {
  std::size_t cloud_bytes = 0;
  for (const ViewScan& v : views) cloud_bytes += v.cloud_in_sensor.size() * 12;
  if (SendMeshInline(part, cloud_bytes)) {
    wire::MeshToProto(part, header.mutable_part()->mutable_inline_());
    return InspectOnce(header, views, progress);
  }
  header.mutable_part()->set_sha256(MeshSha256(part));
  auto first = InspectOnce(header, views, progress);
  if (first.ok() || !IsMeshNotCached(first.status())) return first;
  wire::MeshToProto(part, header.mutable_part()->mutable_inline_());
  return InspectOnce(header, views, progress);
}

absl::StatusOr<v1::InspectResult> RemoteClient::InspectOnce(const v1::PartHeader& header,
                                                            const std::vector<ViewScan>& views,
                                                            const ProgressFn& progress) {
  grpc::ClientContext ctx;
  Prepare(&ctx);
  if (!header.idempotency_key().empty()) ctx.AddMetadata("x-request-id", header.idempotency_key());
  auto stream = stub_->Inspect(&ctx);
  v1::InspectRequest msg;
  *msg.mutable_part() = header;
  bool open = stream->Write(msg);
  for (const ViewScan& v : views) {
    if (!open) break;
    msg.Clear();
    v1::ViewHeader* vh = msg.mutable_view();
    vh->set_name(v.name);
    wire::TransformToProto(v.world_from_sensor, vh->mutable_world_from_sensor());
    vh->set_width(v.cloud_in_sensor.width);
    vh->set_height(v.cloud_in_sensor.height);
    open = stream->Write(msg);
    const char* bytes = reinterpret_cast<const char*>(v.cloud_in_sensor.points.data());
    const std::size_t total = v.cloud_in_sensor.size() * 12;
    for (std::size_t off = 0; open && off < total; off += options_.chunk_bytes) {
      msg.Clear();
      msg.mutable_chunk()->set_xyz(bytes + off, std::min(options_.chunk_bytes, total - off));
      open = stream->Write(msg);
    }
  }
  if (open) {
    msg.Clear();
    msg.mutable_end();
    open = stream->Write(msg);
  }
  stream->WritesDone();
  v1::InspectResponse resp;
  v1::InspectResult result;
  bool have_result = false;
  while (stream->Read(&resp)) {
    if (resp.has_progress() && progress) progress(resp.progress());
    if (resp.has_result()) {
      result = std::move(*resp.mutable_result());
      have_result = true;
    }
  }
  RETURN_IF_ERROR(FromGrpc(stream->Finish()));
  if (!have_result) return absl::InternalError("Inspect stream ended without a result");
  return result;
}

absl::StatusOr<std::string> RemoteClient::Health(const std::string& service) {
  auto health = grpc::health::v1::Health::NewStub(channel_);
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(5));
  if (!options_.auth_token.empty())
    ctx.AddMetadata("authorization", "Bearer " + options_.auth_token);
  grpc::health::v1::HealthCheckRequest req;
  req.set_service(service);
  grpc::health::v1::HealthCheckResponse resp;
  RETURN_IF_ERROR(FromGrpc(health->Check(&ctx, req, &resp)));
  return grpc::health::v1::HealthCheckResponse::ServingStatus_Name(resp.status());
}

absl::Status RemoteClient::WaitUntilReachable(
    double wait_s, const std::function<void(const std::string&)>& waiting) {
  auto health = grpc::health::v1::Health::NewStub(probe_channel_);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(wait_s);
  for (bool told = false;; told = true) {
    grpc::ClientContext ctx;
    ctx.set_wait_for_ready(false);  // a refused connection fails the call at once
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(3));
    if (!options_.auth_token.empty())
      ctx.AddMetadata("authorization", "Bearer " + options_.auth_token);
    grpc::health::v1::HealthCheckResponse resp;
    const grpc::Status st = health->Check(&ctx, grpc::health::v1::HealthCheckRequest(), &resp);
    // Any answer, even a refusal of the token or NOT_SERVING, is a server there.
    if (st.error_code() != grpc::StatusCode::UNAVAILABLE &&
        st.error_code() != grpc::StatusCode::DEADLINE_EXCEEDED)
      return absl::OkStatus();
    const std::string reason = st.error_code() == grpc::StatusCode::DEADLINE_EXCEEDED
                                   ? "no answer within 3 s"
                                   : st.error_message();
    if (std::chrono::steady_clock::now() + std::chrono::milliseconds(250) >= deadline)
      return absl::UnavailableError(
          absl::StrCat("cannot reach surfinspectd at ", options_.target, ": ", reason));
    if (!told && waiting) waiting(reason);
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
  }
}

}  // namespace surfinspect::client
