// surfinspectd: flags and environment -> RunServer.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <csignal>
#include <thread>

#include "absl/status/statusor.h"
#include "absl/strings/ascii.h"
#include "core/io/atomic_file.h"
#include "core/process/buffer_reuse.h"
#include "core/types/status_macros.h"
#include "server/run_server.h"

namespace {

using surfinspect::server::ServerOptions;

// Flags, each with its SURFINSPECT_* environment variable.
void AddFlags(CLI::App& app, ServerOptions& o, std::string& token_file, uint64_t& mesh_cache_mb) {
  app.add_option("--listen", o.listen, "host:port (port 0 = any free port)")
      ->envname("SURFINSPECT_LISTEN")
      ->capture_default_str();
  app.add_option("--metrics-listen", o.metrics_listen, "Prometheus /metrics host:port; empty = off")
      ->envname("SURFINSPECT_METRICS_LISTEN");
  app.add_option("--threads", o.service.threads, "worker threads for heavy calls")
      ->envname("SURFINSPECT_THREADS")
      ->check(CLI::Range(1, 1024))
      ->capture_default_str();
  app.add_option("--max-calls", o.service.max_admitted_calls,
                 "heavy calls admitted at once (running + queued); more get RESOURCE_EXHAUSTED")
      ->envname("SURFINSPECT_MAX_CALLS")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  app.add_option("--max-points", o.service.limits.max_points, "points per cloud / per part")
      ->envname("SURFINSPECT_MAX_POINTS")
      ->capture_default_str();
  app.add_option("--max-triangles", o.service.limits.max_triangles, "triangles per mesh")
      ->envname("SURFINSPECT_MAX_TRIANGLES")
      ->capture_default_str();
  app.add_option("--max-message-mb", o.max_message_mb, "largest gRPC message, MiB")
      ->envname("SURFINSPECT_MAX_MESSAGE_MB")
      ->capture_default_str();
  app.add_option("--max-memory-mb", o.max_memory_mb,
                 "memory the calls may hold at once, MiB; a call that does not fit gets "
                 "RESOURCE_EXHAUSTED before its data is buffered (default: 3/4 of the cgroup "
                 "limit or physical memory, at most 1/2 of ulimit -v)")
      ->envname("SURFINSPECT_MAX_MEMORY_MB");
  app.add_option("--mesh-cache-mb", mesh_cache_mb, "mesh index cache budget, MiB")
      ->envname("SURFINSPECT_MESH_CACHE_MB")
      ->capture_default_str();
  app.add_option("--drain-seconds", o.drain_seconds, "graceful shutdown deadline")
      ->envname("SURFINSPECT_DRAIN_SECONDS")
      ->capture_default_str();
  app.add_option("--max-connection-age", o.max_connection_age_s,
                 "seconds before a connection is recycled (client re-balancing); 0 = never")
      ->envname("SURFINSPECT_MAX_CONNECTION_AGE")
      ->capture_default_str();
  app.add_option("--tls-cert", o.tls_cert_file, "PEM certificate chain")
      ->envname("SURFINSPECT_TLS_CERT");
  app.add_option("--tls-key", o.tls_key_file, "PEM private key")->envname("SURFINSPECT_TLS_KEY");
  app.add_option("--tls-client-ca", o.tls_client_ca_file, "PEM CA for client certificates (mTLS)")
      ->envname("SURFINSPECT_TLS_CLIENT_CA");
  app.add_option("--auth-token-file", token_file, "file holding the bearer token clients must send")
      ->envname("SURFINSPECT_AUTH_TOKEN_FILE");
  app.add_flag("--json-logs", o.service.json_logs, "one JSON object per log line")
      ->envname("SURFINSPECT_JSON_LOGS");
  app.add_option("--fault-inject", o.fault_inject,
                 "test hook: KIND:SITE[:COUNT] makes a guarded callback throw "
                 "(server/fault_hook.h); never in production");
}

// The bearer token from `token_file` (surrounding whitespace stripped).
absl::StatusOr<std::string> ReadToken(const std::string& token_file) {
  ASSIGN_OR_RETURN(auto token, surfinspect::ReadFileToString(token_file, 4096));
  std::string stripped(absl::StripAsciiWhitespace(token));
  if (stripped.empty()) return absl::InvalidArgumentError(token_file + ": the token file is empty");
  return stripped;
}

}  // namespace

int main(int argc, char** argv) {
  // Block SIGTERM/SIGINT before any thread exists (gRPC, TBB and the
  // metrics listener start their own); RunServer waits for them with
  // sigwait on one thread and drains.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  surfinspect::ReuseFreedLargeBuffers();  // every call moves ~10 MB buffers
  ServerOptions o;
  o.service.threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::string token_file;
  uint64_t mesh_cache_mb = 512;
  CLI::App app{"surfinspectd: the surfinspect gRPC inspection service (stateless; mm)"};
  AddFlags(app, o, token_file, mesh_cache_mb);
  CLI11_PARSE(app, argc, argv);

  spdlog::set_default_logger(spdlog::stderr_color_mt("surfinspectd"));
  if (o.service.json_logs)
    spdlog::set_pattern(R"({"time":"%Y-%m-%dT%H:%M:%S.%e%z","level":"%l","log":%v})");
  o.service.mesh_cache_bytes = mesh_cache_mb << 20;
  if (!token_file.empty()) {
    auto token = ReadToken(token_file);
    if (!token.ok()) {
      spdlog::error("{}", std::string(token.status().message()));
      return 2;
    }
    o.service.auth_token = *std::move(token);
  }
  const absl::Status st = surfinspect::server::RunServer(o);
  if (!st.ok()) {
    spdlog::error("{}", std::string(st.message()));
    return 1;
  }
  return 0;
}
