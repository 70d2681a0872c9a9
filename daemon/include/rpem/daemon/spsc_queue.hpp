#pragma once
// Lock-free single-producer single-consumer ring buffer: the only way data crosses between rpemd's
// threads. Capacity fixed at construction (a power of two), storage allocated once; push and pop are
// wait-free, noexcept, allocation-free and real-time safe. A full queue refuses the item (the caller
// counts the drop): a slow consumer never blocks the producer.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <type_traits>

namespace rpem::daemon {

template <typename T>
class SpscQueue {
  // Items are copied in and out; fixed-size Eigen members copy without allocating or throwing.
  static_assert(std::is_copy_assignable_v<T>, "items are copied in and out");

 public:
  /// Capacity is rounded up to a power of two. Allocates; call at start-up only.
  explicit SpscQueue(std::size_t capacity)
      : mask_(round_up(capacity) - 1), slots_(std::make_unique<T[]>(mask_ + 1)) {}

  /// Producer side. False if the queue is full (the item is not stored).
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

  /// Consumer side. False if the queue is empty.
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

  /// Items in the queue (approximate while the other side runs).
  [[nodiscard]] std::size_t size() const noexcept {
    return head_.load(std::memory_order_acquire) - tail_.load(std::memory_order_acquire);
  }
  [[nodiscard]] std::size_t capacity() const noexcept { return mask_ + 1; }

 private:
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
