#include "server/memory_budget.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <string>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace surfinspect::server {
namespace {

constexpr double kMiB = 1024.0 * 1024.0;

// A cgroup file holding a byte count, or "max"; 0 when absent or unlimited.
uint64_t ReadCgroupBytes(const char* path) {
  std::ifstream in(path);
  std::string text;
  if (!(in >> text)) return 0;
  uint64_t bytes = 0;
  if (!absl::SimpleAtoi(text, &bytes)) return 0;  // "max"
  // cgroup v1 writes a page-rounded INT64_MAX for "no limit".
  return bytes >= (uint64_t{1} << 60) ? 0 : bytes;
}

}  // namespace

MemoryBudget::Reservation::Reservation(Reservation&& other) noexcept
    : budget_(other.budget_), bytes_(other.bytes_) {
  other.budget_ = nullptr;
  other.bytes_ = 0;
}

MemoryBudget::Reservation& MemoryBudget::Reservation::operator=(Reservation&& other) noexcept {
  if (this != &other) {
    Release();
    budget_ = other.budget_;
    bytes_ = other.bytes_;
    other.budget_ = nullptr;
    other.bytes_ = 0;
  }
  return *this;
}

MemoryBudget::Reservation::~Reservation() { Release(); }

void MemoryBudget::Reservation::Release() {
  if (budget_ != nullptr) budget_->Return(bytes_);
  budget_ = nullptr;
  bytes_ = 0;
}

void MemoryBudget::Return(uint64_t bytes) {
  const uint64_t now = reserved_.fetch_sub(bytes, std::memory_order_relaxed) - bytes;
  if (observer_) observer_(now, 0);
}

absl::Status MemoryBudget::Refuse(uint64_t bytes, std::string message) {
  refused_.fetch_add(bytes, std::memory_order_relaxed);
  if (observer_) observer_(reserved_bytes(), bytes);
  return absl::ResourceExhaustedError(std::move(message));
}

absl::StatusOr<MemoryBudget::Reservation> MemoryBudget::TryReserve(uint64_t bytes,
                                                                   const std::string& what) {
  if (bytes > budget_)
    return Refuse(bytes,
                  absl::StrFormat(
                      "%s needs %.0f MiB, more than the server's whole memory budget of %.0f MiB; "
                      "send a smaller request or raise --max-memory-mb",
                      what, bytes / kMiB, budget_ / kMiB));
  uint64_t held = reserved_.load(std::memory_order_relaxed);
  do {
    if (held + bytes > budget_)
      return Refuse(
          bytes,
          absl::StrFormat(
              "%s needs %.0f MiB and %.0f MiB of the %.0f MiB memory budget are held by other "
              "calls; retry later",
              what, bytes / kMiB, held / kMiB, budget_ / kMiB));
  } while (!reserved_.compare_exchange_weak(held, held + bytes, std::memory_order_relaxed));
  if (observer_) observer_(held + bytes, 0);
  return Reservation(this, bytes);
}

MemoryLimits DetectMemoryLimits() {
  MemoryLimits m;
  m.physical_bytes = uint64_t(sysconf(_SC_PHYS_PAGES)) * uint64_t(sysconf(_SC_PAGESIZE));
  m.cgroup_bytes = ReadCgroupBytes("/sys/fs/cgroup/memory.max");
  if (m.cgroup_bytes == 0)
    m.cgroup_bytes = ReadCgroupBytes("/sys/fs/cgroup/memory/memory.limit_in_bytes");
  rlimit as{};
  if (getrlimit(RLIMIT_AS, &as) == 0 && as.rlim_cur != RLIM_INFINITY)
    m.address_space_bytes = as.rlim_cur;
  uint64_t base = m.physical_bytes;
  m.source = "physical memory";
  if (m.cgroup_bytes != 0 && m.cgroup_bytes < base) {
    base = m.cgroup_bytes;
    m.source = "cgroup";
  }
  m.default_budget_bytes = base / 4 * 3;
  if (m.address_space_bytes != 0 && m.address_space_bytes / 2 < m.default_budget_bytes) {
    m.default_budget_bytes = m.address_space_bytes / 2;
    m.source = "address-space limit";
  }
  return m;
}

// Measured: the server's peak resident memory (VmHWM) over its resident
// memory before one call, for one view of a plane, filter on, no deviations
// returned, --threads 2. Inspect held 84.1 B/point at 2 M points, 78.2 at
// 5 M and 75.8 at 20 M: 75 B per point plus ~17 MiB per call. That is, per
// point received: the view's cloud as it arrives (12 B, float xyz), the
// filter's labels and kept mask (5 B), the kept points in the world frame
// (12 B) with their view and pixel (8 B), the error map's signed distance,
// triangle id and closest point (4 + 4 + 12 B), and the result's packed
// copies (8 B); the other ~10 B are vector growth. Rounded up to 80, which covers
// the fixed part from ~3.5 M points on.
uint64_t InspectBytesPerPoint() { return 80; }

// Measured as above for ErrorMap: 68.4 B/point at 2 M, 68.0 at 5 M and at
// 20 M points. The cloud is held twice (the request's bytes and the
// PointCloud, 12 + 12 B), plus the error map's arrays (signed distance,
// triangle id, closest point: 20 B); the other ~24 B, not itemized, are the
// conversions' copies and vector growth. Rounded up.
uint64_t UnaryCloudBytesPerPoint() { return 72; }

// MeshIndex::memory_bytes() per triangle, finished index with its hint
// certificates (160 B a triangle) and the mesh's copy in spatial order: see
// tests/server/memory_budget_test.cpp, which checks this is at least twice
// that (407 and 435 B on the demo part and gauge), as Embree's builder holds
// temporary memory of the BVH's order.
uint64_t MeshIndexBytesPerTriangle() { return 900; }

}  // namespace surfinspect::server
