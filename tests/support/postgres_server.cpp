#include "tests/support/postgres_server.h"

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <set>

namespace surfinspect::testing {
namespace {

constexpr char kBin[] = "/usr/lib/postgresql/15/bin";

int FreeLoopbackPort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = 0;
  socklen_t len = sizeof(addr);
  int port = 0;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0 &&
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len) == 0)
    port = ntohs(addr.sin_port);
  ::close(fd);
  return port;
}

}  // namespace

bool PostgresServer::Run(const std::string& command) {
  const std::string full = runner_ + command + " >>" + log_ + ".cmd 2>&1";
  if (std::system(full.c_str()) == 0) return true;
  error_ = "failed: " + command + "\n" + ReadBytes(log_ + ".cmd");
  return false;
}

PostgresServer::PostgresServer() {
  namespace fs = std::filesystem;
  if (!fs::exists(std::string(kBin) + "/initdb")) {
    error_ = std::string(kBin) + "/initdb not found (postgresql-15)";
    return;
  }
  data_ = dir_.File("data");
  socket_ = dir_.File("sock");
  log_ = dir_.File("server.log");
  fs::create_directories(socket_);
  if (::geteuid() == 0) {
    runner_ = "runuser -u postgres -- ";
    if (!Run("true") || std::system(("chown -R postgres " + dir_.path()).c_str()) != 0) return;
  }
  port_ = FreeLoopbackPort();
  if (!Run(std::string(kBin) + "/initdb -D " + data_ + " -A trust -U postgres --no-sync")) return;
  started_ =
      Run(std::string(kBin) + "/pg_ctl -D " + data_ + " -o \"-p " + std::to_string(port_) + " -k " +
          socket_ + " -c listen_addresses=127.0.0.1 -c fsync=off\" -l " + log_ + " -w start");
}

PostgresServer::~PostgresServer() {
  if (started_) Run(std::string(kBin) + "/pg_ctl -D " + data_ + " -m immediate -w stop");
}

std::string PostgresServer::Url(const std::string& db) {
  static std::set<std::string> created;
  const std::string base = "postgresql://postgres@127.0.0.1:" + std::to_string(port_);
  if (db != "postgres" && created.insert(std::to_string(port_) + db).second)
    Run(std::string(kBin) + "/createdb -h 127.0.0.1 -p " + std::to_string(port_) + " -U postgres " +
        db);
  return base + "/" + db;
}

}  // namespace surfinspect::testing
