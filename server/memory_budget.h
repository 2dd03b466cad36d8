// The server's memory budget: every call reserves the bytes it will hold
// (its clouds, result arrays, a mesh index it builds) before it holds them,
// and a call that does not fit is refused with RESOURCE_EXHAUSTED at once,
// before its data is buffered, with a retry hint. Clients retry that code.
// So overload shows as retryable refusals instead of std::bad_alloc halfway
// through some call, and the reserved total never passes the budget.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>

#include "absl/status/statusor.h"

namespace surfinspect::server {

class MemoryBudget {
 public:
  // What one call holds. Releases its bytes when destroyed; movable.
  class Reservation {
   public:
    Reservation() = default;
    Reservation(Reservation&& other) noexcept;
    Reservation& operator=(Reservation&& other) noexcept;
    Reservation(const Reservation&) = delete;
    Reservation& operator=(const Reservation&) = delete;
    ~Reservation();
    uint64_t bytes() const { return bytes_; }
    void Release();

   private:
    friend class MemoryBudget;
    Reservation(MemoryBudget* budget, uint64_t bytes) : budget_(budget), bytes_(bytes) {}
    MemoryBudget* budget_ = nullptr;
    uint64_t bytes_ = 0;
  };

  explicit MemoryBudget(uint64_t budget_bytes) : budget_(budget_bytes) {}

  // Called after every reservation, release and refusal with the reserved
  // total and the bytes just refused (0 unless refused); for the metrics.
  using Observer = std::function<void(uint64_t reserved_bytes, uint64_t refused_bytes)>;
  void SetObserver(Observer observer) { observer_ = std::move(observer); }

  // Reserves `bytes` for `what` (named in the refusal), or RESOURCE_EXHAUSTED
  // when the reserved total would pass the budget: "retry later" when other
  // calls hold the room, "never fits" when `bytes` alone exceeds the budget.
  absl::StatusOr<Reservation> TryReserve(uint64_t bytes, const std::string& what);

  uint64_t budget_bytes() const { return budget_; }
  uint64_t reserved_bytes() const { return reserved_.load(std::memory_order_relaxed); }
  // Bytes of calls refused so far, for the metrics.
  uint64_t refused_bytes() const { return refused_.load(std::memory_order_relaxed); }

 private:
  void Return(uint64_t bytes);
  absl::Status Refuse(uint64_t bytes, std::string message);
  const uint64_t budget_;
  Observer observer_;
  std::atomic<uint64_t> reserved_{0};
  std::atomic<uint64_t> refused_{0};
};

// Where the default budget comes from, with the figures found.
struct MemoryLimits {
  uint64_t physical_bytes = 0;
  uint64_t cgroup_bytes = 0;         // 0 = no cgroup limit
  uint64_t address_space_bytes = 0;  // RLIMIT_AS; 0 = unlimited
  uint64_t default_budget_bytes = 0;
  std::string source;  // "cgroup", "physical memory" or "address-space limit"
};

// The default budget: 3/4 of the tighter of the cgroup's memory limit (the
// container case; cgroup v2 memory.max or v1 memory.limit_in_bytes) and the
// physical memory, and at most 1/2 of an address-space limit (RLIMIT_AS
// counts thread stacks and the allocator's arenas too, which are not
// resident). The rest is the process's own: code, mesh cache, gRPC buffers.
MemoryLimits DetectMemoryLimits();

// Bytes a call holds per point it receives, by the data it keeps (see
// memory_budget.cpp for the breakdown).
uint64_t InspectBytesPerPoint();
uint64_t UnaryCloudBytesPerPoint();
// Bytes an inline mesh holds per triangle while its index is built.
uint64_t MeshIndexBytesPerTriangle();

}  // namespace surfinspect::server
