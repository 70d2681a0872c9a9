#pragma once
// Lock-free single-producer single-consumer ring buffer: how rpemd's threads hand each other samples,
// commands and reports (beside it only a few atomics cross: the stop flags, the loop's heartbeat and
// calibrated wake-ahead, its started flag; docs/rpemd.md, "Threads").
// A queue is made with its two ends, and only so: SpscQueue<T>::make(capacity) returns one Producer and
// one Consumer, each move-only. Whoever holds the producer is the queue's one producer, whoever holds the
// consumer its one consumer; a second producer or consumer of a queue does not compile (copying an end
// is deleted; tests/compile_fail/). The ends share the storage: it lives until both are gone. Where
// assertions are on (rpem/core/assert.hpp), each end also checks that one thread uses it: the first to
// push (pop) after it was made or handed over.
// Capacity fixed at construction (a power of two), storage allocated once; push and pop are wait-free,
// noexcept, allocation-free and real-time safe. A full queue refuses the item (the caller counts the
// drop): a slow consumer never blocks the producer.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <thread>
#include <type_traits>

#include "rpem/core/assert.hpp"

namespace rpem::daemon {

template <typename T>
class SpscQueue {
  // Items are copied in and out; fixed-size Eigen members copy without allocating or throwing.
  static_assert(std::is_copy_assignable_v<T>, "items are copied in and out");

  /// What both ends are: a share of the queue, move-only (copying one would make a second producer or
  /// consumer), and — where assertions are on (rpem/core/assert.hpp) — used by one thread: the first to
  /// use it after it was made or handed over. Default-constructed or moved from: the end of no queue.
  class End {
   public:
    End() noexcept = default;
    End(End&& other) noexcept : queue_(std::move(other.queue_)) {}  // handed over: a new first user
    End& operator=(End&& other) noexcept {
      queue_ = std::move(other.queue_);
#if RPEM_ASSERTIONS
      user_ = {};
#endif
      return *this;
    }
    End(const End&) = delete;
    End& operator=(const End&) = delete;

    /// Items in the queue (approximate while the other end runs).
    [[nodiscard]] std::size_t size() const noexcept { return queue_->size(); }
    [[nodiscard]] std::size_t capacity() const noexcept { return queue_->capacity(); }

   protected:
    explicit End(std::shared_ptr<SpscQueue> queue) noexcept : queue_(std::move(queue)) {}
    /// The queue, for this end's one thread.
    SpscQueue& use() noexcept {
      RPEM_ASSERT(queue_ != nullptr, "an end of a queue is used, not a default-constructed or moved-from one");
#if RPEM_ASSERTIONS
      const std::thread::id me = std::this_thread::get_id();
      if (user_ == std::thread::id()) user_ = me;
      RPEM_ASSERT(user_ == me, "an end of an SpscQueue is used by one thread: the queue's one producer (consumer)");
#endif
      return *queue_;
    }

   private:
    std::shared_ptr<SpscQueue> queue_;
#if RPEM_ASSERTIONS
    std::thread::id user_;  ///< the end's one thread, once it has been used
#endif
  };

 public:
  /// The end that pushes: the queue's one producer.
  class Producer : public End {
   public:
    Producer() noexcept = default;
    /// False if the queue is full (the item is not stored).
    bool push(const T& item) noexcept { return this->use().push(item); }

   private:
    friend SpscQueue;
    explicit Producer(std::shared_ptr<SpscQueue> queue) noexcept : End(std::move(queue)) {}
  };

  /// The end that pops: the queue's one consumer.
  class Consumer : public End {
   public:
    Consumer() noexcept = default;
    /// False if the queue is empty.
    bool pop(T& item) noexcept { return this->use().pop(item); }

   private:
    friend SpscQueue;
    explicit Consumer(std::shared_ptr<SpscQueue> queue) noexcept : End(std::move(queue)) {}
  };

  struct Ends {
    Producer producer;
    Consumer consumer;
  };

  /// A queue of `capacity` items (rounded up to a power of two) and its two ends. Allocates; call at
  /// start-up only.
  [[nodiscard]] static Ends make(std::size_t capacity) {
    const std::shared_ptr<SpscQueue> queue(new SpscQueue(capacity));
    return {Producer(queue), Consumer(queue)};
  }

  SpscQueue(const SpscQueue&) = delete;
  SpscQueue& operator=(const SpscQueue&) = delete;

 private:
  explicit SpscQueue(std::size_t capacity) : mask_(round_up(capacity) - 1), slots_(std::make_unique<T[]>(mask_ + 1)) {}

  bool push(const T& item) noexcept {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_cache_ > mask_) {
      tail_cache_ = tail_.load(std::memory_order_acquire);
      if (head - tail_cache_ > mask_) return false;
    }
    slots_[head & mask_] = item;
    head_.store(head + 1, std::memory_order_release);
    return true;
  }

  bool pop(T& item) noexcept {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_cache_) {
      head_cache_ = head_.load(std::memory_order_acquire);
      if (tail == head_cache_) return false;
    }
    item = slots_[tail & mask_];
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }

  [[nodiscard]] std::size_t size() const noexcept {
    return head_.load(std::memory_order_acquire) - tail_.load(std::memory_order_acquire);
  }
  [[nodiscard]] std::size_t capacity() const noexcept { return mask_ + 1; }

  static std::size_t round_up(std::size_t n) {
    std::size_t c = 2;
    while (c < n) c <<= 1;
    return c;
  }

  static constexpr std::size_t kLine = 64;  // keep producer and consumer indices on separate cache lines
  const std::size_t mask_;
  std::unique_ptr<T[]> slots_;
  alignas(kLine) std::atomic<std::size_t> head_{0};
  std::size_t tail_cache_ = 0;  // producer's view of tail
  alignas(kLine) std::atomic<std::size_t> tail_{0};
  std::size_t head_cache_ = 0;  // consumer's view of head
};

}  // namespace rpem::daemon
