// Admission control and execution for CPU-heavy calls: a fixed set of
// worker threads and a bounded number of admitted jobs (running + queued).
// A job that does not fit is refused at once, so the caller can answer
// RESOURCE_EXHAUSTED instead of queueing without bound (and running out of
// memory on large clouds). Jobs run inside one shared tbb::task_arena, so the
// parallel kernels of all calls together use at most `threads` cores. A job
// that throws is logged and dropped (server/guarded.h); the worker lives on.
#pragma once

#include <tbb/task_arena.h>

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace surfinspect::server {

class WorkPool {
 public:
  WorkPool(int threads, int max_admitted);
  ~WorkPool();  // runs what is queued, then joins
  WorkPool(const WorkPool&) = delete;
  WorkPool& operator=(const WorkPool&) = delete;

  // False (and `job` not run) when max_admitted jobs are already admitted.
  // If it throws (std::bad_alloc while queueing), `job` is not admitted.
  bool TrySubmit(std::function<void()> job);
  int admitted() const;

 private:
  void Worker();
  tbb::task_arena arena_;
  const int max_admitted_;
  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::deque<std::function<void()>> queue_;
  int admitted_ = 0;
  bool stopping_ = false;
  std::vector<std::thread> workers_;
};

}  // namespace surfinspect::server
