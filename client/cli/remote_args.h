// The --server family of options shared by every remote-capable command.
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <string>

#include "client/remote/remote_client.h"

namespace surfinspect::cli {

struct RemoteArgs {
  std::string server;  // empty = run in-process
  std::string tls_ca, tls_cert, tls_key, tls_server_name, token_file;
  double timeout_s = 600;
  double wait_for_server_s = 0;  // 0: a server that does not answer fails the command at once
  bool remote() const { return !server.empty(); }
};

void AddRemoteOptions(CLI::App* cmd, RemoteArgs& args);
// Connects, checks that the server answers (waiting up to
// --wait-for-server), or throws CommandFailed naming the address and why.
std::unique_ptr<client::RemoteClient> Connect(const RemoteArgs& args);

}  // namespace surfinspect::cli
