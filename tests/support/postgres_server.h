// A real PostgreSQL 15 server for tests: initdb in a temporary folder and
// pg_ctl on a free loopback port, run as the `postgres` user when the test
// runs as root (initdb refuses root), trust authentication, stopped and
// removed at the end. Skips (available() false) when the binaries are absent.
#pragma once

#include <string>

#include "tests/support/temp_dir.h"

namespace surfinspect::testing {

class PostgresServer {
 public:
  PostgresServer();
  ~PostgresServer();
  PostgresServer(const PostgresServer&) = delete;
  PostgresServer& operator=(const PostgresServer&) = delete;

  bool available() const { return started_; }
  const std::string& error() const { return error_; }
  // postgresql://postgres@127.0.0.1:PORT/DB; `db` is created on first use.
  std::string Url(const std::string& db = "postgres");
  int port() const { return port_; }

 private:
  bool Run(const std::string& command);
  TempDir dir_;
  std::string data_, log_, socket_, runner_;
  int port_ = 0;
  bool started_ = false;
  std::string error_;
};

}  // namespace surfinspect::testing
