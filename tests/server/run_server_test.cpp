// server/run_server.cpp: the warning for a server open to the network.
#include "server/run_server.h"

#include <gtest/gtest.h>

namespace surfinspect::server {
namespace {

TEST(RunServer, AnUnprotectedListenerBeyondLoopbackIsWarnedAbout) {
  ServerOptions o;
  for (const char* open : {"0.0.0.0:50051", "[::]:50051", "10.0.0.5:50051", "cell-pc:50051"}) {
    o.listen = open;
    const std::string w = ExposureWarning(o);
    EXPECT_NE(w.find(std::string("listening on ") + open + " beyond loopback"), std::string::npos)
        << open << ": " << w;
    EXPECT_NE(w.find("--tls-cert"), std::string::npos);
  }
  for (const char* local : {"127.0.0.1:0", "localhost:50051", "[::1]:50051", "unix:/run/s.sock"}) {
    o.listen = local;
    EXPECT_EQ(ExposureWarning(o), "") << local;
  }
  o.listen = "0.0.0.0:50051";
  o.service.auth_token = "secret";
  EXPECT_EQ(ExposureWarning(o), "") << "a token protects it";
  o.service.auth_token.clear();
  o.tls_cert_file = "server.pem";
  EXPECT_EQ(ExposureWarning(o), "") << "TLS protects it";
}

}  // namespace
}  // namespace surfinspect::server
