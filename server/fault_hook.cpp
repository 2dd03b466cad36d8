#include "server/fault_hook.h"

#include <mutex>
#include <new>
#include <stdexcept>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"

namespace surfinspect::server {
namespace fault_internal {
std::atomic<bool> armed{false};
}  // namespace fault_internal

namespace {

enum class Kind { kBadAlloc, kRuntimeError, kUnknown };

struct Fault {
  Kind kind;
  std::string site;  // METHOD.STEP
  int remaining;
};

std::mutex& FaultsMutex() {
  static std::mutex mu;
  return mu;
}

std::vector<Fault>& Faults() {
  static std::vector<Fault> faults;
  return faults;
}

bool KnownSite(const std::string& site) {
  for (const char* s : {"Start", "OnReadDone", "OnWriteDone", "Compute", "Finish"})
    if (site == absl::StrCat("Inspect.", s)) return true;
  for (const char* method : {"Filter", "Calibrate", "Register", "ErrorMap"})
    for (const char* s : {"Start", "Run", "Done"})
      if (site == absl::StrCat(method, ".", s)) return true;
  return false;
}

[[noreturn]] void Throw(Kind kind, const std::string& site) {
  switch (kind) {
    case Kind::kBadAlloc:
      throw std::bad_alloc();
    case Kind::kRuntimeError:
      throw std::runtime_error("fault injected at " + site);
    case Kind::kUnknown:
      throw 42;
  }
  throw 42;
}

}  // namespace

absl::Status ArmFault(const std::string& spec) {
  const std::vector<std::string> parts = absl::StrSplit(spec, ':');
  const std::string where = absl::StrCat("--fault-inject ", spec, ": ");
  if (parts.size() < 2 || parts.size() > 3)
    return absl::InvalidArgumentError(absl::StrCat(where, "expected KIND:SITE[:COUNT]"));
  Fault f{Kind::kBadAlloc, parts[1], 1};
  if (parts[0] == "runtime_error")
    f.kind = Kind::kRuntimeError;
  else if (parts[0] == "unknown")
    f.kind = Kind::kUnknown;
  else if (parts[0] != "bad_alloc")
    return absl::InvalidArgumentError(
        absl::StrCat(where, "KIND must be bad_alloc, runtime_error or unknown"));
  if (!KnownSite(f.site))
    return absl::InvalidArgumentError(
        absl::StrCat(where, "SITE must name a guarded call, e.g. Inspect.OnReadDone"));
  if (parts.size() == 3 && (!absl::SimpleAtoi(parts[2], &f.remaining) || f.remaining < 1))
    return absl::InvalidArgumentError(absl::StrCat(where, "COUNT must be an integer >= 1"));
  std::lock_guard<std::mutex> lock(FaultsMutex());
  Faults().push_back(std::move(f));
  fault_internal::armed.store(true, std::memory_order_relaxed);
  return absl::OkStatus();
}

void fault_internal::InjectIfArmed(const char* method, const char* step) {
  const std::string site = absl::StrCat(method, ".", step);
  Kind kind;
  {
    std::lock_guard<std::mutex> lock(FaultsMutex());
    auto it = Faults().begin();
    while (it != Faults().end() && !(it->site == site && it->remaining > 0)) ++it;
    if (it == Faults().end()) return;
    --it->remaining;
    kind = it->kind;
  }
  Throw(kind, site);
}

}  // namespace surfinspect::server
