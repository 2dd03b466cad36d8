#include "client/agent/retry.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

namespace surfinspect::client {

void SleepUnlessStopped(double seconds, const std::atomic<bool>& stop) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point end =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(
                         std::chrono::duration<double>(std::max(0.0, seconds)));
  while (!stop.load()) {
    const Clock::time_point now = Clock::now();
    if (now >= end) return;
    std::this_thread::sleep_for(
        std::min<Clock::duration>(end - now, std::chrono::milliseconds(50)));
  }
}

double BackoffWait(const BackoffSettings& settings, int retry, std::mt19937_64& rng) {
  const double cap =
      std::min(settings.max_s, settings.initial_s * std::pow(2.0, std::min(retry, 60)));
  return std::uniform_real_distribution<double>(0.0, cap)(rng);
}

RetryResult RetryWithBackoff(const std::function<absl::Status()>& call,
                             const std::function<bool(const absl::Status&)>& retryable,
                             const BackoffSettings& settings, const RetryHooks& hooks,
                             std::mt19937_64& rng, const std::atomic<bool>& stop) {
  RetryResult r;
  while (true) {
    if (stop.load()) {
      r.end = RetryEnd::kStopped;
      return r;
    }
    r.status = call();
    ++r.calls;
    if (r.status.ok()) {
      r.end = RetryEnd::kOk;
      return r;
    }
    if (!retryable(r.status)) {
      r.end = RetryEnd::kFailed;
      return r;
    }
    if (settings.max_attempts > 0 && r.calls >= settings.max_attempts) {
      r.end = RetryEnd::kExhausted;
      return r;
    }
    if (stop.load()) {
      r.end = RetryEnd::kStopped;
      return r;
    }
    const double wait = BackoffWait(settings, r.waits, rng);
    if (hooks.on_retry) hooks.on_retry(r.status, r.calls, wait);
    hooks.sleep(wait, stop);
    ++r.waits;
  }
}

}  // namespace surfinspect::client
