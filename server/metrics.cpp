#include "server/metrics.h"

#include <prometheus/counter.h>
#include <prometheus/exposer.h>
#include <prometheus/gauge.h>
#include <prometheus/histogram.h>
#include <prometheus/registry.h>
#include <prometheus/text_serializer.h>

#include "absl/strings/str_cat.h"

namespace surfinspect::server {

absl::StatusOr<std::unique_ptr<Metrics>> Metrics::Create(const std::string& listen) {
  std::unique_ptr<Metrics> m(new Metrics());
  m->registry_ = std::make_shared<prometheus::Registry>();
  m->rpcs_ = &prometheus::BuildCounter()
                  .Name("surfinspect_rpcs_total")
                  .Help("RPCs finished, by method and gRPC status code")
                  .Register(*m->registry_);
  m->latency_ = &prometheus::BuildHistogram()
                     .Name("surfinspect_rpc_duration_seconds")
                     .Help("RPC wall time from arrival to status, by method")
                     .Register(*m->registry_);
  m->points_ = &prometheus::BuildCounter()
                    .Name("surfinspect_points_processed_total")
                    .Help("Cloud points received for processing")
                    .Register(*m->registry_)
                    .Add({});
  auto& cache = prometheus::BuildCounter()
                    .Name("surfinspect_mesh_cache_lookups_total")
                    .Help("Mesh index cache lookups by result")
                    .Register(*m->registry_);
  m->cache_hits_ = &cache.Add({{"result", "hit"}});
  m->cache_misses_ = &cache.Add({{"result", "miss"}});
  m->in_flight_ = &prometheus::BuildGauge()
                       .Name("surfinspect_calls_in_flight")
                       .Help("Heavy calls admitted and not yet finished")
                       .Register(*m->registry_)
                       .Add({});
  m->memory_budget_ = &prometheus::BuildGauge()
                           .Name("surfinspect_memory_budget_bytes")
                           .Help("Bytes the calls may reserve at once (--max-memory-mb)")
                           .Register(*m->registry_)
                           .Add({});
  m->memory_reserved_ = &prometheus::BuildGauge()
                             .Name("surfinspect_memory_reserved_bytes")
                             .Help("Bytes reserved by the calls in progress")
                             .Register(*m->registry_)
                             .Add({});
  m->memory_refused_ = &prometheus::BuildCounter()
                            .Name("surfinspect_memory_refused_bytes_total")
                            .Help("Bytes of calls refused with RESOURCE_EXHAUSTED for the budget")
                            .Register(*m->registry_)
                            .Add({});
  if (!listen.empty()) {
    try {
      m->exposer_ = std::make_unique<prometheus::Exposer>(listen, 1);
      m->exposer_->RegisterCollectable(m->registry_);
    } catch (const std::exception& e) {
      return absl::UnavailableError(
          absl::StrCat("metrics: cannot listen on ", listen, ": ", e.what()));
    }
  }
  return m;
}

Metrics::~Metrics() = default;

void Metrics::RecordRpc(const std::string& method, const std::string& code, double seconds) {
  rpcs_->Add({{"method", method}, {"code", code}}).Increment();
  latency_
      ->Add({{"method", method}},
            prometheus::Histogram::BucketBoundaries{0.001, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5,
                                                    1, 2.5, 5, 10, 30})
      .Observe(seconds);
}

void Metrics::AddPoints(uint64_t points) { points_->Increment(double(points)); }
void Metrics::MeshCacheHit() { cache_hits_->Increment(); }
void Metrics::MeshCacheMiss() { cache_misses_->Increment(); }
void Metrics::CallStarted() { in_flight_->Increment(); }
void Metrics::CallEnded() { in_flight_->Decrement(); }
void Metrics::SetMemoryBudget(uint64_t bytes) { memory_budget_->Set(double(bytes)); }
void Metrics::SetMemoryReserved(uint64_t reserved_bytes, uint64_t refused_bytes) {
  memory_reserved_->Set(double(reserved_bytes));
  if (refused_bytes != 0) memory_refused_->Increment(double(refused_bytes));
}

std::string Metrics::Scrape() const {
  return prometheus::TextSerializer().Serialize(registry_->Collect());
}

}  // namespace surfinspect::server
