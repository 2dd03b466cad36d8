#include "server/run_server.h"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>
#include <signal.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <thread>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "core/io/atomic_file.h"
#include "core/types/status_macros.h"
#include "server/fault_hook.h"
#include "server/memory_budget.h"

namespace surfinspect::server {
namespace {

absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> Credentials(const ServerOptions& o) {
  if (o.tls_cert_file.empty() && o.tls_key_file.empty()) {
    if (!o.tls_client_ca_file.empty())
      return absl::InvalidArgumentError("--tls-client-ca needs --tls-cert and --tls-key");
    return grpc::InsecureServerCredentials();
  }
  if (o.tls_cert_file.empty() || o.tls_key_file.empty())
    return absl::InvalidArgumentError("TLS needs both --tls-cert and --tls-key");
  ASSIGN_OR_RETURN(auto cert, ReadFileToString(o.tls_cert_file, 1 << 20));
  ASSIGN_OR_RETURN(auto key, ReadFileToString(o.tls_key_file, 1 << 20));
  grpc::SslServerCredentialsOptions ssl;
  ssl.pem_key_cert_pairs.push_back({key, cert});
  if (!o.tls_client_ca_file.empty()) {
    ASSIGN_OR_RETURN(auto ca, ReadFileToString(o.tls_client_ca_file, 1 << 20));
    ssl.pem_root_certs = ca;
    ssl.client_certificate_request = GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY;
  }
  return grpc::SslServerCredentials(ssl);
}

// --max-memory-mb, or the default from the machine's limits (logged).
uint64_t MemoryBudgetBytes(const ServerOptions& options) {
  if (options.max_memory_mb != 0) return options.max_memory_mb << 20;
  const MemoryLimits m = DetectMemoryLimits();
  spdlog::info(
      "memory budget {} MiB from the {} (physical {} MiB, cgroup {} MiB, RLIMIT_AS {} MiB)",
      m.default_budget_bytes >> 20, m.source, m.physical_bytes >> 20, m.cgroup_bytes >> 20,
      m.address_space_bytes >> 20);
  return m.default_budget_bytes;
}

}  // namespace

std::string ExposureWarning(const ServerOptions& options) {
  if (!options.tls_cert_file.empty() || !options.service.auth_token.empty()) return "";
  if (absl::StartsWith(options.listen, "unix:")) return "";  // the file's permissions guard it
  std::string host = options.listen.substr(0, options.listen.rfind(':'));
  if (host.size() > 1 && host.front() == '[' && host.back() == ']')
    host = host.substr(1, host.size() - 2);
  if (host == "localhost" || host == "::1" || absl::StartsWith(host, "127.")) return "";
  return absl::StrCat("listening on ", options.listen,
                      " beyond loopback with neither TLS nor a token: anyone who reaches this "
                      "port can send work and read results. Give --tls-cert/--tls-key and "
                      "--auth-token-file, or listen on 127.0.0.1 behind a proxy "
                      "(docs/deployment.md)");
}

absl::Status RunServer(const ServerOptions& options) {
  if (options.max_message_mb < 1 || options.max_message_mb > 2000)
    return absl::InvalidArgumentError("--max-message-mb must be in 1..2000");
  if (options.max_memory_mb > (uint64_t{1} << 24))
    return absl::InvalidArgumentError("--max-memory-mb must be at most 16777216 (16 TiB)");
  if (options.service.threads < 1 || options.service.max_admitted_calls < 1)
    return absl::InvalidArgumentError("--threads and --max-calls must be >= 1");
  for (const std::string& spec : options.fault_inject)
    if (absl::Status st = ArmFault(spec); !st.ok()) return st;
  ASSIGN_OR_RETURN(auto creds, Credentials(options));
  ASSIGN_OR_RETURN(auto metrics, Metrics::Create(options.metrics_listen));

  // Handle SIGTERM/SIGINT on one thread of our own: they are blocked (main
  // blocks them first thing; this repeats it for other callers), and the
  // waiter below takes them with sigwait.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  ServiceConfig config = options.service;
  config.memory_budget_bytes = MemoryBudgetBytes(options);
  config.max_message_bytes = uint64_t(options.max_message_mb) << 20;
  InspectionService service(config, metrics.get());
  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  int port = 0;
  builder.AddListeningPort(options.listen, creds, &port);
  builder.SetMaxReceiveMessageSize(options.max_message_mb << 20);
  builder.SetMaxSendMessageSize(options.max_message_mb << 20);
  // gRPC's own buffers (messages being received or sent) get a quarter of
  // the budget on top of it; past that gRPC stops reading from clients
  // instead of allocating.
  grpc::ResourceQuota quota("surfinspectd");
  quota.Resize(static_cast<std::size_t>(
      std::max<uint64_t>(config.memory_budget_bytes / 4, uint64_t(options.max_message_mb) << 21)));
  builder.SetResourceQuota(quota);
  if (options.max_connection_age_s > 0) {
    builder.AddChannelArgument(GRPC_ARG_MAX_CONNECTION_AGE_MS, options.max_connection_age_s * 1000);
    builder.AddChannelArgument(GRPC_ARG_MAX_CONNECTION_AGE_GRACE_MS, 30000);
  }
  builder.RegisterService(&service);
  std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  if (!server || port == 0)
    return absl::UnavailableError(absl::StrCat("cannot listen on ", options.listen));
  grpc::HealthCheckServiceInterface* health = server->GetHealthCheckService();
  health->SetServingStatus(true);
  health->SetServingStatus("surfinspect.v1.InspectionService", true);

  const std::string host = options.listen.substr(0, options.listen.rfind(':'));
  std::printf("surfinspectd listening on %s:%d\n", host.c_str(), port);
  std::fflush(stdout);
  spdlog::info(
      "serving on {}:{} ({} worker threads, {} admitted calls, memory budget {} MiB, TLS {}, "
      "token {}, metrics {})",
      host, port, options.service.threads, options.service.max_admitted_calls,
      config.memory_budget_bytes >> 20,
      options.tls_cert_file.empty() ? "off" : (options.tls_client_ca_file.empty() ? "on" : "mTLS"),
      options.service.auth_token.empty() ? "off" : "on",
      options.metrics_listen.empty() ? "off" : options.metrics_listen);

  if (const std::string warning = ExposureWarning(options); !warning.empty())
    spdlog::warn("{}", warning);

  std::thread waiter([&] {
    int sig = 0;
    sigwait(&signals, &sig);
    spdlog::info("signal {}: draining (up to {} s)", sig, options.drain_seconds);
    health->Shutdown();  // NOT_SERVING for everyone, frozen
    server->Shutdown(std::chrono::system_clock::now() +
                     std::chrono::milliseconds(static_cast<int64_t>(options.drain_seconds * 1000)));
  });
  server->Wait();
  waiter.join();
  spdlog::info("stopped");
  return absl::OkStatus();
}

}  // namespace surfinspect::server
