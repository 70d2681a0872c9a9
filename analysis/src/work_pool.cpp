#include "rpem/analysis/work_pool.hpp"

#include <sched.h>

#include <algorithm>
#include <atomic>
#include <exception>

namespace rpem::analysis {

/// One parallel_for: its indices, handed out one at a time, and how many have returned.
struct WorkPool::Loop {
  Loop(const WorkPool& p, std::size_t count, const std::function<void(std::size_t)>& f) : pool(p), n(count), body(f) {}
  const WorkPool& pool;
  const std::size_t n;
  const std::function<void(std::size_t)>& body;
  std::atomic<std::size_t> next{0};
  std::atomic<std::size_t> done{0};
  std::atomic<bool> failed{false};
  std::mutex mutex;  ///< guards error
  std::exception_ptr error;

  [[nodiscard]] bool open() const noexcept { return next.load() < n; }
  /// Runs indices until none is left to take.
  void run() {
    for (std::size_t i = next++; i < n; i = next++) {
      if (!failed.load()) {
        try {
          body(i);
        } catch (...) {
          const std::lock_guard lock(mutex);
          if (!error) error = std::current_exception();
          failed = true;
        }
      }
      if (++done == n) {
        // The caller waits on the pool's signal (helping other loops meanwhile): under the pool's mutex, so
        // that it cannot miss it between its test and its wait.
        { const std::lock_guard lock(pool.mutex_); }
        pool.wake_.notify_all();
      }
    }
  }
};

WorkPool::WorkPool(int threads) {
  for (int t = 1; t < threads; ++t) workers_.emplace_back([this] { work(); });
}

WorkPool::~WorkPool() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (std::thread& t : workers_) t.join();
}

const WorkPool& WorkPool::serial() {
  static const WorkPool pool(1);
  return pool;
}

void WorkPool::parallel_for(std::size_t n, const std::function<void(std::size_t)>& body) const {
  if (workers_.empty() || n <= 1) {
    for (std::size_t i = 0; i < n; ++i) body(i);
    return;
  }
  const auto loop = std::make_shared<Loop>(*this, n, body);
  {
    const std::lock_guard lock(mutex_);
    loops_.push_back(loop);
  }
  wake_.notify_all();
  loop->run();
  // Its indices are all taken; until the last one returns, this thread helps whatever loop still has
  // indices (the nested loops of the ones still running, newest first) instead of waiting idle: a round's
  // fits, say, end at different times, and the last one's replays would otherwise run on one thread.
  std::unique_lock lock(mutex_);
  loops_.erase(std::find(loops_.begin(), loops_.end(), loop));
  while (loop->done.load() != n) {
    if (const std::shared_ptr<Loop> other = newest_open()) {
      lock.unlock();
      other->run();
      lock.lock();
      continue;
    }
    wake_.wait(lock);
  }
  lock.unlock();
  if (loop->error) std::rethrow_exception(loop->error);
}

std::shared_ptr<WorkPool::Loop> WorkPool::newest_open() const {
  const auto newest = std::find_if(loops_.rbegin(), loops_.rend(), [](const std::shared_ptr<Loop>& l) { return l->open(); });
  return newest == loops_.rend() ? nullptr : *newest;
}

void WorkPool::work() {
  for (;;) {
    std::shared_ptr<Loop> loop;
    {
      std::unique_lock lock(mutex_);
      // The newest loop first: a nested one, whose caller waits for it inside an older loop's index. The loop
      // the wait found is the one taken: its indices are taken without the lock, so a second look may find
      // none left (its run() then returns at once).
      wake_.wait(lock, [&] { return stopping_ || (loop = newest_open()) != nullptr; });
      if (stopping_) return;
    }
    loop->run();
  }
}

int available_cpus() noexcept {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) == 0) return std::max(1, CPU_COUNT(&set));
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

}  // namespace rpem::analysis
