// Retrying a call on transient failures: exponential backoff with full
// jitter (Brooker, "Exponential Backoff And Jitter", AWS architecture blog,
// 2015): before retry n (0-based) wait uniform in
//     [0, min(max_s, initial_s · 2^n)].
// The sleep is injected, so tests run without waiting; a stop request ends
// a wait early and no call starts after it.
#pragma once

#include <atomic>
#include <functional>
#include <random>

#include "absl/status/status.h"

namespace surfinspect::client {

struct BackoffSettings {
  double initial_s = 0.5;  // cap of the first wait, s
  double max_s = 15.0;     // cap of any wait, s
  int max_attempts = 0;    // calls per operation on retryable errors; 0 = unlimited
};

// Waits `seconds` or until `stop` is set, whichever comes first.
using SleepFn = std::function<void(double seconds, const std::atomic<bool>& stop)>;
// The real clock, checking `stop` every 50 milliseconds.
void SleepUnlessStopped(double seconds, const std::atomic<bool>& stop);

// The wait before retry `retry` (0 = the first retry), s.
double BackoffWait(const BackoffSettings& settings, int retry, std::mt19937_64& rng);

struct RetryHooks {
  SleepFn sleep = SleepUnlessStopped;
  // Called before each wait with the failure, the calls made so far and the wait (s).
  std::function<void(const absl::Status&, int calls, double wait_s)> on_retry;
};

enum class RetryEnd {
  kOk,         // the call succeeded
  kFailed,     // a non-retryable error
  kExhausted,  // retryable errors until max_attempts
  kStopped,    // stop was requested before the call succeeded
};

struct RetryResult {
  RetryEnd end = RetryEnd::kOk;
  absl::Status status;  // of the last call (OK when none was made)
  int calls = 0;        // calls made
  int waits = 0;        // backoff waits
};

// Calls `call` until it succeeds, fails with a non-retryable status
// (`retryable` false), makes max_attempts calls, or `stop` is set.
RetryResult RetryWithBackoff(const std::function<absl::Status()>& call,
                             const std::function<bool(const absl::Status&)>& retryable,
                             const BackoffSettings& settings, const RetryHooks& hooks,
                             std::mt19937_64& rng, const std::atomic<bool>& stop);

}  // namespace surfinspect::client
