#include "server/work_pool.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <future>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

namespace surfinspect::server {
namespace {

// Long enough never to expire on a loaded 2-core machine when the pool is
// right; it only bounds how long a broken pool can hang a test.
constexpr std::chrono::milliseconds kLong{10000};
// How long a test watches for something that must not happen.
constexpr std::chrono::milliseconds kBrief{50};

// Jobs block on it until the test opens it, so the test decides when they end.
class Gate {
 public:
  void Open() {
    {
      std::lock_guard<std::mutex> lock(mu_);
      open_ = true;
    }
    cv_.notify_all();
  }
  void Wait() {
    std::unique_lock<std::mutex> lock(mu_);
    cv_.wait_for(lock, kLong, [this] { return open_; });
  }

 private:
  std::mutex mu_;
  std::condition_variable cv_;
  bool open_ = false;
};

// Counts events (jobs started) and lets the test wait for the n-th.
class Counter {
 public:
  void Add() {
    {
      std::lock_guard<std::mutex> lock(mu_);
      ++count_;
    }
    cv_.notify_all();
  }
  bool WaitFor(int n, std::chrono::milliseconds timeout) {
    std::unique_lock<std::mutex> lock(mu_);
    return cv_.wait_for(lock, timeout, [&] { return count_ >= n; });
  }
  int value() {
    std::lock_guard<std::mutex> lock(mu_);
    return count_;
  }

 private:
  std::mutex mu_;
  std::condition_variable cv_;
  int count_ = 0;
};

// A slot is released just after its job returns, so the count is polled.
bool WaitUntilAdmitted(const WorkPool& pool, int n) {
  const auto until = std::chrono::steady_clock::now() + kLong;
  while (pool.admitted() != n) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

void RaiseTo(std::atomic<int>& peak, int now) {
  int seen = peak.load();
  while (now > seen && !peak.compare_exchange_weak(seen, now)) {
  }
}

TEST(WorkPool, RunsAnAdmittedJobOnAWorkerAndItsResultComesBack) {
  WorkPool pool(2, 4);
  auto result = std::make_shared<std::promise<long>>();
  auto ran_on = std::make_shared<std::promise<std::thread::id>>();
  std::future<long> sum = result->get_future();
  std::future<std::thread::id> thread = ran_on->get_future();
  ASSERT_TRUE(pool.TrySubmit([result, ran_on] {
    long s = 0;
    for (long i = 1; i <= 1000; ++i) s += i;
    ran_on->set_value(std::this_thread::get_id());
    result->set_value(s);
  }));
  ASSERT_EQ(sum.wait_for(kLong), std::future_status::ready);
  EXPECT_EQ(sum.get(), 500500);
  EXPECT_NE(thread.get(), std::this_thread::get_id());
  EXPECT_TRUE(WaitUntilAdmitted(pool, 0));
}

TEST(WorkPool, RefusesAtOnceWhenMaxAdmittedAreHeldAndNeverRunsTheRefusedJob) {
  Gate gate;
  Counter started;
  std::atomic<bool> refused_ran{false};
  {
    WorkPool pool(1, 2);
    for (int i = 0; i < 2; ++i)
      ASSERT_TRUE(pool.TrySubmit([&] {
        started.Add();
        gate.Wait();
      }));
    ASSERT_TRUE(started.WaitFor(1, kLong));
    EXPECT_EQ(pool.admitted(), 2);  // one running, one queued
    EXPECT_FALSE(pool.TrySubmit([&] { refused_ran = true; }));
    EXPECT_EQ(pool.admitted(), 2);
    // One worker: the queued job waits until the running one is done.
    EXPECT_FALSE(started.WaitFor(2, kBrief));
    gate.Open();
    EXPECT_TRUE(started.WaitFor(2, kLong));
    EXPECT_TRUE(WaitUntilAdmitted(pool, 0));
    EXPECT_TRUE(pool.TrySubmit([] {}));  // the slots are back
  }
  EXPECT_FALSE(refused_ran.load());
}

TEST(WorkPool, AThrowingJobReleasesItsSlotAndTheWorkerLivesOn) {
  WorkPool pool(1, 1);
  ASSERT_TRUE(pool.TrySubmit([] { throw std::runtime_error("job failed"); }));
  ASSERT_TRUE(WaitUntilAdmitted(pool, 0));
  ASSERT_TRUE(pool.TrySubmit([] { throw 42; }));  // not a std::exception
  ASSERT_TRUE(WaitUntilAdmitted(pool, 0));
  // With one slot and one thread, this runs only if both were given back.
  auto ran = std::make_shared<std::promise<void>>();
  std::future<void> done = ran->get_future();
  ASSERT_TRUE(pool.TrySubmit([ran] { ran->set_value(); }));
  EXPECT_EQ(done.wait_for(kLong), std::future_status::ready);
}

TEST(WorkPool, RunsExactlyThreadsJobsAtOnce) {
  constexpr int kThreads = 2;
  constexpr int kJobs = 6;
  Gate gate;
  Counter started;
  std::atomic<int> running{0};
  std::atomic<int> peak{0};
  {
    WorkPool pool(kThreads, kJobs);
    for (int i = 0; i < kJobs; ++i)
      ASSERT_TRUE(pool.TrySubmit([&] {
        RaiseTo(peak, ++running);
        started.Add();
        gate.Wait();
        --running;
      }));
    ASSERT_TRUE(started.WaitFor(kThreads, kLong));
    EXPECT_FALSE(started.WaitFor(kThreads + 1, kBrief));  // no third thread picks one up
    EXPECT_EQ(pool.admitted(), kJobs);
    gate.Open();
  }
  EXPECT_EQ(started.value(), kJobs);
  EXPECT_EQ(peak.load(), kThreads);
}

TEST(WorkPool, ZeroThreadsAndZeroAdmissionsMeanOneOfEach) {
  Gate gate;
  Counter started;
  WorkPool pool(0, 0);
  ASSERT_TRUE(pool.TrySubmit([&] {
    started.Add();
    gate.Wait();
  }));
  EXPECT_TRUE(started.WaitFor(1, kLong));  // a worker exists
  EXPECT_FALSE(pool.TrySubmit([] {}));     // and one job is the bound
  gate.Open();
}

// The kernels of a job share the pool's arena, so a job sees `threads` slots.
TEST(WorkPool, JobsRunInsideAnArenaOfThreadsSlots) {
  // A size unlike the default arena's, which a job run outside it would see.
  const int threads = tbb::this_task_arena::max_concurrency() == 3 ? 2 : 3;
  WorkPool pool(threads, 1);
  auto seen = std::make_shared<std::promise<int>>();
  std::future<int> slots = seen->get_future();
  ASSERT_TRUE(pool.TrySubmit([seen] { seen->set_value(tbb::this_task_arena::max_concurrency()); }));
  ASSERT_EQ(slots.wait_for(kLong), std::future_status::ready);
  EXPECT_EQ(slots.get(), threads);
}

TEST(WorkPool, DestructionRefusesNewJobsAndRunsTheQueuedOnes) {
  constexpr int kMax = 1000;
  Gate gate;
  Counter started;
  std::atomic<int> queued_ran{0};
  std::atomic<int> late_accepted{0};
  std::atomic<int> late_ran{0};
  std::atomic<bool> refused_with_room{false};
  auto pool = std::make_unique<WorkPool>(1, kMax);
  ASSERT_TRUE(pool->TrySubmit([&] {
    started.Add();
    gate.Wait();
  }));
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(pool->TrySubmit([&] { ++queued_ran; }));
  ASSERT_TRUE(started.WaitFor(1, kLong));
  // Submits until the destructor below has begun (a refusal with room left
  // can only mean the pool is stopping), then lets the running job end.
  std::thread prober([&, p = pool.get()] {
    while (p->TrySubmit([&] { ++late_ran; })) {
      ++late_accepted;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    refused_with_room = p->admitted() < kMax;
    gate.Open();
  });
  pool.reset();
  prober.join();
  EXPECT_TRUE(refused_with_room.load());
  EXPECT_EQ(queued_ran.load(), 4);
  EXPECT_EQ(late_ran.load(), late_accepted.load());
}

TEST(WorkPool, ConcurrentSubmittersNeverPassTheBoundAndEveryAdmittedJobRuns) {
  constexpr int kMax = 3;
  std::atomic<int> accepted{0};
  std::atomic<int> ran{0};
  std::atomic<int> peak{0};
  {
    WorkPool pool(2, kMax);
    std::vector<std::thread> submitters;
    for (int t = 0; t < 4; ++t)
      submitters.emplace_back([&] {
        for (int i = 0; i < 500; ++i)
          if (pool.TrySubmit([&] {
                RaiseTo(peak, pool.admitted());
                ++ran;
              }))
            ++accepted;
      });
    for (auto& s : submitters) s.join();
  }
  EXPECT_GT(accepted.load(), 0);
  EXPECT_EQ(ran.load(), accepted.load());
  EXPECT_GE(peak.load(), 1);
  EXPECT_LE(peak.load(), kMax);
}

}  // namespace
}  // namespace surfinspect::server
