// Prometheus metrics (prometheus-cpp), served on /metrics by a separate
// HTTP listener: RPC counts by method and code, latency histograms, points
// processed, mesh-cache hits and misses, and calls in flight.
#pragma once

#include <memory>
#include <string>

#include "absl/status/statusor.h"

namespace prometheus {
class Registry;
class Exposer;
class Counter;
class Gauge;
template <typename T>
class Family;
class Histogram;
}  // namespace prometheus

namespace surfinspect::server {

class Metrics {
 public:
  // `listen` like "127.0.0.1:9464"; empty = collect but do not serve.
  static absl::StatusOr<std::unique_ptr<Metrics>> Create(const std::string& listen);
  ~Metrics();

  void RecordRpc(const std::string& method, const std::string& code, double seconds);
  void AddPoints(uint64_t points);
  void MeshCacheHit();
  void MeshCacheMiss();
  void CallStarted();
  void CallEnded();
  // The memory budget (server/memory_budget.h): its size, what calls hold
  // now, and bytes refused (added to a counter).
  void SetMemoryBudget(uint64_t bytes);
  void SetMemoryReserved(uint64_t reserved_bytes, uint64_t refused_bytes);
  // The text exposition, for tests and for `--metrics-listen` off.
  std::string Scrape() const;

 private:
  Metrics() = default;
  std::shared_ptr<prometheus::Registry> registry_;
  std::unique_ptr<prometheus::Exposer> exposer_;
  prometheus::Family<prometheus::Counter>* rpcs_ = nullptr;
  prometheus::Family<prometheus::Histogram>* latency_ = nullptr;
  prometheus::Counter* points_ = nullptr;
  prometheus::Counter* cache_hits_ = nullptr;
  prometheus::Counter* cache_misses_ = nullptr;
  prometheus::Gauge* in_flight_ = nullptr;
  prometheus::Gauge* memory_budget_ = nullptr;
  prometheus::Gauge* memory_reserved_ = nullptr;
  prometheus::Counter* memory_refused_ = nullptr;
};

}  // namespace surfinspect::server
