// A call's cancellation flag, polled by the core loops, that also remembers
// when it was raised, so the log can say how long the work took to stop
// (the service promises well under a tenth of a second).
#pragma once

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>

namespace surfinspect::server {

class CancelSignal {
 public:
  // From gRPC's OnCancel (client cancel, deadline, or lost connection).
  void Raise() {
    if (raised_at_ns_.load(std::memory_order_relaxed) == 0)
      raised_at_ns_.store(NowNs(), std::memory_order_relaxed);
    flag_.store(true);
  }
  const std::atomic<bool>& flag() const { return flag_; }
  bool raised() const { return flag_.load(); }
  // Milliseconds since Raise(); NaN if it was never raised.
  double MillisecondsSinceRaised() const {
    const int64_t at = raised_at_ns_.load(std::memory_order_relaxed);
    return raised() && at != 0 ? (NowNs() - at) / 1e6 : NAN;
  }

 private:
  static int64_t NowNs() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }
  std::atomic<bool> flag_{false};
  std::atomic<int64_t> raised_at_ns_{0};
};

}  // namespace surfinspect::server
