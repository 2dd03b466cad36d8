// RunServer: builds and runs surfinspectd until SIGTERM or SIGINT, then
// drains: the health service turns NOT_SERVING (so load balancers stop
// sending), new calls are refused, in-flight calls get `drain_seconds` to
// finish, then the rest are cancelled.
#pragma once

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "server/inspection_service.h"

namespace surfinspect::server {

struct ServerOptions {
  std::string listen = "127.0.0.1:50051";  // host:port; port 0 picks a free one
  std::string metrics_listen;              // e.g. 127.0.0.1:9464; empty = off
  ServiceConfig service;
  std::string tls_cert_file, tls_key_file;  // both set = TLS
  std::string tls_client_ca_file;           // set = mTLS (client certificates required)
  int max_message_mb = 64;                  // per message, both directions
  // What the calls may hold at once, MiB (server/memory_budget.h); 0 = the
  // default from the cgroup limit, physical memory and RLIMIT_AS.
  uint64_t max_memory_mb = 0;
  double drain_seconds = 20;  // graceful-shutdown deadline
  // Close connections after this age so clients re-resolve and spread over
  // new replicas (HTTP/2 pins every call to one connection). 0 = never.
  int max_connection_age_s = 300;
  // Test hook (server/fault_hook.h): each KIND:SITE[:COUNT] arms a fault.
  std::vector<std::string> fault_inject;
};

// The warning for a server that listens beyond loopback with neither TLS
// nor a token (anyone who reaches the port can send work and read
// results); "" when it listens on loopback only or is protected.
std::string ExposureWarning(const ServerOptions& options);

// Blocks until a shutdown signal. Prints "surfinspectd listening on
// HOST:PORT" on stdout once serving (tests read the chosen port from it).
absl::Status RunServer(const ServerOptions& options);

}  // namespace surfinspect::server
