#include "client/agent/retry.h"

#include <gtest/gtest.h>

#include <chrono>
#include <vector>

namespace surfinspect::client {
namespace {

bool Retryable(const absl::Status& st) { return absl::IsUnavailable(st); }

TEST(BackoffWaitTest, FullJitterUnderADoublingCap) {
  const BackoffSettings s{0.5, 4.0, 0};
  std::mt19937_64 rng(3);
  for (int retry = 0; retry < 8; ++retry) {
    const double cap = std::min(4.0, 0.5 * (1 << retry));
    double lo = 1e9, hi = 0;
    for (int i = 0; i < 2000; ++i) {
      const double w = BackoffWait(s, retry, rng);
      ASSERT_GE(w, 0.0);
      ASSERT_LE(w, cap);
      lo = std::min(lo, w);
      hi = std::max(hi, w);
    }
    // Uniform over [0, cap]: 2000 draws reach both ends to within 1 %.
    EXPECT_LT(lo, 0.01 * cap) << retry;
    EXPECT_GT(hi, 0.99 * cap) << retry;
  }
  EXPECT_LE(BackoffWait(s, 100000, rng), 4.0);
}

TEST(RetryWithBackoffTest, RetriesRetryableErrorsUntilOk) {
  std::vector<absl::Status> answers = {absl::UnavailableError("a"), absl::UnavailableError("b"),
                                       absl::OkStatus()};
  int calls = 0;
  std::vector<double> waits, reported;
  RetryHooks hooks;
  hooks.sleep = [&](double s, const std::atomic<bool>&) { waits.push_back(s); };
  hooks.on_retry = [&](const absl::Status&, int n, double s) {
    EXPECT_EQ(n, static_cast<int>(reported.size()) + 1);
    reported.push_back(s);
  };
  std::mt19937_64 rng(1);
  std::atomic<bool> stop{false};
  const RetryResult r = RetryWithBackoff([&] { return answers[calls++]; }, Retryable,
                                         BackoffSettings{}, hooks, rng, stop);
  EXPECT_EQ(r.end, RetryEnd::kOk);
  EXPECT_EQ(r.calls, 3);
  EXPECT_EQ(r.waits, 2);
  EXPECT_EQ(waits, reported);
}

TEST(RetryWithBackoffTest, NonRetryableEndsAtOnceAndMaxAttemptsCaps) {
  std::mt19937_64 rng(1);
  std::atomic<bool> stop{false};
  RetryHooks hooks;
  int waits = 0;
  hooks.sleep = [&](double, const std::atomic<bool>&) { ++waits; };
  RetryResult r = RetryWithBackoff([] { return absl::InvalidArgumentError("no"); }, Retryable,
                                   BackoffSettings{}, hooks, rng, stop);
  EXPECT_EQ(r.end, RetryEnd::kFailed);
  EXPECT_EQ(r.calls, 1);
  EXPECT_TRUE(absl::IsInvalidArgument(r.status));
  r = RetryWithBackoff([] { return absl::UnavailableError("down"); }, Retryable,
                       BackoffSettings{0.5, 1, 3}, hooks, rng, stop);
  EXPECT_EQ(r.end, RetryEnd::kExhausted);
  EXPECT_EQ(r.calls, 3);
  EXPECT_EQ(waits, 2);
}

TEST(RetryWithBackoffTest, StopEndsTheWaitAndNoCallFollows) {
  std::mt19937_64 rng(1);
  std::atomic<bool> stop{false};
  RetryHooks hooks;
  hooks.sleep = [&](double, const std::atomic<bool>&) { stop.store(true); };
  int calls = 0;
  const RetryResult r = RetryWithBackoff(
      [&] {
        ++calls;
        return absl::UnavailableError("down");
      },
      Retryable, BackoffSettings{}, hooks, rng, stop);
  EXPECT_EQ(r.end, RetryEnd::kStopped);
  EXPECT_EQ(calls, 1);
  EXPECT_TRUE(absl::IsUnavailable(r.status));
  const RetryResult none = RetryWithBackoff([&] { return ++calls, absl::OkStatus(); }, Retryable,
                                            BackoffSettings{}, hooks, rng, stop);
  EXPECT_EQ(none.end, RetryEnd::kStopped);
  EXPECT_EQ(none.calls, 0);
}

TEST(SleepUnlessStoppedTest, ReturnsAtOnceWhenStopped) {
  std::atomic<bool> stop{true};
  const auto t0 = std::chrono::steady_clock::now();
  SleepUnlessStopped(30.0, stop);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(1));
  stop.store(false);
  const auto t1 = std::chrono::steady_clock::now();
  SleepUnlessStopped(0.02, stop);
  EXPECT_GE(std::chrono::steady_clock::now() - t1, std::chrono::milliseconds(20));
}

}  // namespace
}  // namespace surfinspect::client
