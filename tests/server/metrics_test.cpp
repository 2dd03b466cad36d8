#include "server/metrics.h"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <utility>

namespace surfinspect::server {
namespace {

bool StartsWith(const std::string& s, const std::string& prefix) {
  return s.compare(0, prefix.size(), prefix) == 0;
}

// The samples of a text exposition: series ("name{labels}") -> value. The
// values are parsed, so the tests do not depend on how numbers are printed.
std::map<std::string, double> Samples(const std::string& text) {
  std::map<std::string, double> samples;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.empty() || line[0] == '#') continue;
    const std::size_t space = line.rfind(' ');
    if (space == std::string::npos) continue;
    samples[line.substr(0, space)] = std::stod(line.substr(space + 1));
  }
  return samples;
}

// One series' value; NaN when the exposition lacks it, so any EXPECT_EQ fails.
double Sample(const Metrics& metrics, const std::string& series) {
  const auto samples = Samples(metrics.Scrape());
  const auto it = samples.find(series);
  return it == samples.end() ? NAN : it->second;
}

// The cumulative count of `method`'s latency bucket with upper bound `le` s
// (the label is parsed too, "+Inf" included); NaN when there is none.
double Bucket(const Metrics& metrics, const std::string& method, double le) {
  const std::string prefix =
      "surfinspect_rpc_duration_seconds_bucket{method=\"" + method + "\",le=\"";
  for (const auto& sample : Samples(metrics.Scrape()))
    if (StartsWith(sample.first, prefix) && std::stod(sample.first.substr(prefix.size())) == le)
      return sample.second;
  return NAN;
}

// Collects without serving; null (and a failed expectation) on error.
std::unique_ptr<Metrics> Unserved() {
  auto metrics = Metrics::Create("");
  EXPECT_TRUE(metrics.ok()) << metrics.status();
  if (!metrics.ok()) return nullptr;
  return *std::move(metrics);
}

// A loopback port that a listening socket holds for the object's lifetime.
class HeldPort {
 public:
  HeldPort() : fd_(::socket(AF_INET, SOCK_STREAM, 0)) {
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);  // port 0: the kernel picks one
    socklen_t len = sizeof(addr);
    if (fd_ >= 0 && ::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0 &&
        ::listen(fd_, 1) == 0 && ::getsockname(fd_, reinterpret_cast<sockaddr*>(&addr), &len) == 0)
      port_ = ntohs(addr.sin_port);
  }
  ~HeldPort() {
    if (fd_ >= 0) ::close(fd_);
  }
  HeldPort(const HeldPort&) = delete;
  HeldPort& operator=(const HeldPort&) = delete;
  int port() const { return port_; }  // 0 if it could not listen

 private:
  const int fd_;
  int port_ = 0;
};

TEST(Metrics, SeriesWithoutPerCallLabelsStartAtZero) {
  const auto metrics = Unserved();
  ASSERT_NE(metrics.get(), nullptr);
  const std::string text = metrics->Scrape();
  const auto samples = Samples(text);
  for (const char* series :
       {"surfinspect_points_processed_total",
        "surfinspect_mesh_cache_lookups_total{result=\"hit\"}",
        "surfinspect_mesh_cache_lookups_total{result=\"miss\"}", "surfinspect_calls_in_flight",
        "surfinspect_memory_budget_bytes", "surfinspect_memory_reserved_bytes",
        "surfinspect_memory_refused_bytes_total"}) {
    const auto it = samples.find(series);
    ASSERT_TRUE(it != samples.end()) << series << " missing from\n" << text;
    EXPECT_EQ(it->second, 0.0) << series;
  }
}

// Three ErrorMap calls (OK after 0.003 s and 0.2 s, CANCELLED after 0.04 s)
// and one Filter (INVALID_ARGUMENT after 0.0005 s).
std::unique_ptr<Metrics> WithFourRpcs() {
  auto metrics = Unserved();
  if (!metrics) return metrics;
  metrics->RecordRpc("ErrorMap", "OK", 0.003);
  metrics->RecordRpc("ErrorMap", "OK", 0.2);
  metrics->RecordRpc("ErrorMap", "CANCELLED", 0.04);
  metrics->RecordRpc("Filter", "INVALID_ARGUMENT", 0.0005);
  return metrics;
}

TEST(Metrics, RpcsAreCountedByMethodAndCode) {
  const auto metrics = WithFourRpcs();
  ASSERT_NE(metrics.get(), nullptr);
  EXPECT_EQ(Sample(*metrics, R"(surfinspect_rpcs_total{code="OK",method="ErrorMap"})"), 2.0);
  EXPECT_EQ(Sample(*metrics, R"(surfinspect_rpcs_total{code="CANCELLED",method="ErrorMap"})"), 1.0);
  EXPECT_EQ(Sample(*metrics, R"(surfinspect_rpcs_total{code="INVALID_ARGUMENT",method="Filter"})"),
            1.0);
  // No count leaks into a method and code pair that never happened.
  const double none = Sample(*metrics, R"(surfinspect_rpcs_total{code="OK",method="Filter"})");
  EXPECT_TRUE(std::isnan(none) || none == 0.0) << none;
}

TEST(Metrics, LatencyIsOneHistogramPerMethodOverAllCodes) {
  const auto metrics = WithFourRpcs();
  ASSERT_NE(metrics.get(), nullptr);
  EXPECT_EQ(Sample(*metrics, R"(surfinspect_rpc_duration_seconds_count{method="ErrorMap"})"), 3.0);
  EXPECT_NEAR(Sample(*metrics, R"(surfinspect_rpc_duration_seconds_sum{method="ErrorMap"})"), 0.243,
              1e-6);
  EXPECT_EQ(Sample(*metrics, R"(surfinspect_rpc_duration_seconds_count{method="Filter"})"), 1.0);
  // Cumulative buckets: each counts the observations at or below its bound.
  EXPECT_EQ(Bucket(*metrics, "ErrorMap", 0.001), 0.0);
  EXPECT_EQ(Bucket(*metrics, "ErrorMap", 0.005), 1.0);
  EXPECT_EQ(Bucket(*metrics, "ErrorMap", 0.05), 2.0);
  EXPECT_EQ(Bucket(*metrics, "ErrorMap", 0.25), 3.0);
  EXPECT_EQ(Bucket(*metrics, "ErrorMap", 30), 3.0);
  EXPECT_EQ(Bucket(*metrics, "ErrorMap", INFINITY), 3.0);
  EXPECT_EQ(Bucket(*metrics, "Filter", 0.001), 1.0);
}

TEST(Metrics, PointsAccumulateExactly) {
  const auto metrics = Unserved();
  ASSERT_NE(metrics.get(), nullptr);
  metrics->AddPoints(1000);
  metrics->AddPoints(20'000'000);
  metrics->AddPoints(uint64_t{1} << 40);
  EXPECT_EQ(Sample(*metrics, "surfinspect_points_processed_total"),
            static_cast<double>((uint64_t{1} << 40) + 20'001'000));
}

TEST(Metrics, MeshCacheHitsAndMissesAreSeparateSeries) {
  const auto metrics = Unserved();
  ASSERT_NE(metrics.get(), nullptr);
  metrics->MeshCacheHit();
  metrics->MeshCacheMiss();
  metrics->MeshCacheHit();
  EXPECT_EQ(Sample(*metrics, R"(surfinspect_mesh_cache_lookups_total{result="hit"})"), 2.0);
  EXPECT_EQ(Sample(*metrics, R"(surfinspect_mesh_cache_lookups_total{result="miss"})"), 1.0);
}

TEST(Metrics, CallsInFlightFollowStartsAndEnds) {
  const auto metrics = Unserved();
  ASSERT_NE(metrics.get(), nullptr);
  for (int i = 0; i < 3; ++i) metrics->CallStarted();
  EXPECT_EQ(Sample(*metrics, "surfinspect_calls_in_flight"), 3.0);
  metrics->CallEnded();
  EXPECT_EQ(Sample(*metrics, "surfinspect_calls_in_flight"), 2.0);
  metrics->CallEnded();
  metrics->CallEnded();
  EXPECT_EQ(Sample(*metrics, "surfinspect_calls_in_flight"), 0.0);
}

// Reserved bytes are a level (set), refused bytes a running total (added).
TEST(Metrics, MemoryGaugesAreSetAndRefusalsAccumulate) {
  const auto metrics = Unserved();
  ASSERT_NE(metrics.get(), nullptr);
  metrics->SetMemoryBudget(uint64_t{8} << 30);
  EXPECT_EQ(Sample(*metrics, "surfinspect_memory_budget_bytes"), 8589934592.0);
  metrics->SetMemoryReserved(500, 0);
  EXPECT_EQ(Sample(*metrics, "surfinspect_memory_reserved_bytes"), 500.0);
  EXPECT_EQ(Sample(*metrics, "surfinspect_memory_refused_bytes_total"), 0.0);
  metrics->SetMemoryReserved(200, 300);
  EXPECT_EQ(Sample(*metrics, "surfinspect_memory_reserved_bytes"), 200.0);
  EXPECT_EQ(Sample(*metrics, "surfinspect_memory_refused_bytes_total"), 300.0);
  metrics->SetMemoryReserved(0, 50);
  EXPECT_EQ(Sample(*metrics, "surfinspect_memory_reserved_bytes"), 0.0);
  EXPECT_EQ(Sample(*metrics, "surfinspect_memory_refused_bytes_total"), 350.0);
}

// A listener that cannot start is an error from Create, not a silent
// server without /metrics.
TEST(Metrics, CreateIsUnavailableWhenTheListenAddressIsTaken) {
  const HeldPort held;
  ASSERT_NE(held.port(), 0);
  const std::string address = "127.0.0.1:" + std::to_string(held.port());
  const auto metrics = Metrics::Create(address);
  ASSERT_FALSE(metrics.ok());
  EXPECT_EQ(metrics.status().code(), absl::StatusCode::kUnavailable);
  EXPECT_NE(metrics.status().message().find(address), std::string::npos) << metrics.status();
}

}  // namespace
}  // namespace surfinspect::server
