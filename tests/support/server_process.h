// Starts a real surfinspectd on a free loopback port for integration tests
// (STYLE lesson 11) and stops it with SIGTERM (graceful) or SIGKILL.
#pragma once

#include <sys/types.h>

#include <string>
#include <vector>

namespace surfinspect::testing {

// Path of a binary built next to the test executable (build/bin/NAME).
std::string BinPath(const std::string& name);

class ServerProcess {
 public:
  // Extra flags go after --listen 127.0.0.1:0. Waits until it listens.
  explicit ServerProcess(const std::vector<std::string>& extra_args = {});
  ~ServerProcess();  // SIGKILL if still running
  ServerProcess(const ServerProcess&) = delete;
  ServerProcess& operator=(const ServerProcess&) = delete;

  bool started() const { return port_ > 0; }
  int port() const { return port_; }
  std::string target() const { return "127.0.0.1:" + std::to_string(port_); }
  // SIGTERM and wait; returns the exit status (or -1).
  int Terminate();
  void Kill();
  std::string log_path() const { return log_; }

 private:
  pid_t pid_ = -1;
  int port_ = 0;
  std::string log_;
};

}  // namespace surfinspect::testing
