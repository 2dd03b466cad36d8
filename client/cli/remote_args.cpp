#include "client/cli/remote_args.h"

#include <spdlog/spdlog.h>

#include "absl/strings/ascii.h"
#include "client/cli/commands.h"
#include "core/io/atomic_file.h"

namespace surfinspect::cli {

void AddRemoteOptions(CLI::App* cmd, RemoteArgs& a) {
  cmd->add_option("--server", a.server,
                  "run on surfinspectd at this gRPC target (host:port, dns:///..., "
                  "ipv4:a:p,b:p); default: in-process")
      ->envname("SURFINSPECT_SERVER");
  cmd->add_option("--tls-ca", a.tls_ca, "PEM CA that signed the server certificate (enables TLS)");
  cmd->add_option("--tls-cert", a.tls_cert, "client certificate (mTLS)");
  cmd->add_option("--tls-key", a.tls_key, "client key (mTLS)");
  cmd->add_option("--tls-server-name", a.tls_server_name,
                  "expected name in the server certificate");
  cmd->add_option("--token-file", a.token_file, "file with the bearer token")
      ->envname("SURFINSPECT_TOKEN_FILE");
  cmd->add_option("--timeout", a.timeout_s, "per-call deadline, seconds")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--wait-for-server", a.wait_for_server_s,
                  "wait up to this long for the server to answer, seconds (default 0: fail at "
                  "once when it refuses, after 3 s when it is silent)")
      ->check(CLI::NonNegativeNumber);
}

std::unique_ptr<client::RemoteClient> Connect(const RemoteArgs& a) {
  client::RemoteOptions o;
  o.target = a.server;
  o.tls_ca_file = a.tls_ca;
  o.tls_cert_file = a.tls_cert;
  o.tls_key_file = a.tls_key;
  o.tls_server_name = a.tls_server_name;
  o.timeout_s = a.timeout_s;
  if (!a.token_file.empty())
    o.auth_token =
        std::string(absl::StripAsciiWhitespace(Take(ReadFileToString(a.token_file, 4096))));
  std::unique_ptr<client::RemoteClient> client = Take(client::RemoteClient::Connect(o));
  Check(client->WaitUntilReachable(a.wait_for_server_s, [&a](const std::string& why) {
    spdlog::info("waiting up to {} s for surfinspectd at {} ({})", a.wait_for_server_s, a.server,
                 why);
  }));
  return client;
}

}  // namespace surfinspect::cli
