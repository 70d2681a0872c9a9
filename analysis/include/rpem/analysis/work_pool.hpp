#pragma once
// A fixed set of threads that run the indices of a loop (`rpem diagnose --jobs N`: the blocks of a replay,
// the candidates of a round). The calling thread takes part, so a pool of one thread is the plain loop.
// Loops nest: a body may run a loop of its own on the same pool — its caller works on its own indices and
// idle threads help, so no thread ever waits for a task nobody runs; a caller whose indices are all taken
// helps the loops still open (the others' nested ones) until its own last index returns. Which thread runs
// an index is not fixed; what it computes must not depend on it: bodies write to their own index's slot,
// and callers combine the slots in index order, so that the results are the same, to the last bit, for
// any number of threads.

#include <condition_variable>
#include <cstddef>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace rpem::analysis {

class WorkPool {
 public:
  /// `threads` ≥ 1: the caller and threads − 1 workers.
  explicit WorkPool(int threads = 1);
  ~WorkPool();
  WorkPool(const WorkPool&) = delete;
  WorkPool& operator=(const WorkPool&) = delete;

  [[nodiscard]] int threads() const noexcept { return static_cast<int>(workers_.size()) + 1; }

  /// Runs body(i) for every i in [0, n) and returns when all have returned. An exception thrown by a body
  /// is rethrown here (the first one; the indices not yet started are skipped).
  void parallel_for(std::size_t n, const std::function<void(std::size_t)>& body) const;

  /// The pool of one thread (the caller alone).
  [[nodiscard]] static const WorkPool& serial();

 private:
  struct Loop;
  void work();
  /// The newest loop with indices not yet taken, if any (mutex_ held).
  [[nodiscard]] std::shared_ptr<Loop> newest_open() const;

  std::vector<std::thread> workers_;
  mutable std::mutex mutex_;
  mutable std::condition_variable wake_;
  mutable std::vector<std::shared_ptr<Loop>> loops_;  ///< loops with indices not yet taken
  bool stopping_ = false;
};

/// The CPUs this process may run on (its affinity mask), at least 1: `--jobs`' default.
[[nodiscard]] int available_cpus() noexcept;

}  // namespace rpem::analysis
