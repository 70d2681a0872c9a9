#pragma once
// Real-time set-up of a thread (call from the thread itself, at start-up): scheduling policy and
// priority, CPU affinity, a prefaulted stack; and mlockall for the process. Each returns an empty
// string on success or the reason it failed (the caller decides whether that is fatal).

#include <string>

namespace rpem::daemon {

struct ThreadPolicy {
  bool fifo = false;  ///< SCHED_FIFO, else SCHED_OTHER
  int priority = 0;   ///< 1–99 for SCHED_FIFO
  int cpu = -1;       ///< pin to this CPU; −1: no pinning
  bool operator==(const ThreadPolicy&) const = default;
};

[[nodiscard]] std::string apply_thread_policy(const ThreadPolicy& policy);
[[nodiscard]] std::string lock_memory();
/// Holds the CPU's wake-up latency at most `us` (PM QoS via /dev/cpu_dma_latency, as cyclictest does),
/// keeping deep idle states away for as long as the returned descriptor stays open. Returns the
/// descriptor, or −1 with the reason in `problem`.
[[nodiscard]] int request_cpu_dma_latency(int us, std::string& problem);
/// Touches `bytes` of stack so later use does not page-fault.
void prefault_stack(std::size_t bytes);
/// Names the calling thread (top, ps -L).
void name_thread(const char* name);
/// One iteration's hint to the CPU inside a busy-wait (x86 PAUSE, ARM YIELD): no system call.
inline void spin_pause() noexcept {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__) || defined(__arm__)
  asm volatile("yield");
#endif
}

}  // namespace rpem::daemon
