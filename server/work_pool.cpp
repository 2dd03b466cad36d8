#include "server/work_pool.h"

#include <algorithm>

#include "server/guarded.h"

namespace surfinspect::server {

WorkPool::WorkPool(int threads, int max_admitted)
    : arena_(std::max(1, threads)), max_admitted_(std::max(1, max_admitted)) {
  for (int i = 0; i < std::max(1, threads); ++i) workers_.emplace_back([this] { Worker(); });
}

WorkPool::~WorkPool() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stopping_ = true;
  }
  cv_.notify_all();
  for (auto& t : workers_) t.join();
}

bool WorkPool::TrySubmit(std::function<void()> job) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (stopping_ || admitted_ >= max_admitted_) return false;
    queue_.push_back(std::move(job));  // first: if it throws, nothing was admitted
    ++admitted_;
  }
  cv_.notify_one();
  return true;
}

int WorkPool::admitted() const {
  std::lock_guard<std::mutex> lock(mu_);
  return admitted_;
}

void WorkPool::Worker() {
  for (;;) {
    std::function<void()> job;
    {
      std::unique_lock<std::mutex> lock(mu_);
      cv_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping and drained
      job = std::move(queue_.front());
      queue_.pop_front();
    }
    // A job guards its own call; this guard keeps the thread alive if one does not.
    Guarded("WorkPool", "Worker", [&] { arena_.execute([&] { job(); }); });
    std::lock_guard<std::mutex> lock(mu_);
    --admitted_;
  }
}

}  // namespace surfinspect::server
