#pragma once
// The emulated VESC's time (`rpem sim --vesc`; docs/can-vesc.md, "Emulator", "Drive time"): the drive runs
// on demand, never paced by a wall clock. Its time is the host's receive clock (kernel receive timestamps
// of the polls) minus an origin; a poll that arrived at drive time t makes the drive run every control
// cycle from its last state up to t, and only then does the firmware read (and reset) its averages
// (sim/vesc_motor.hpp). A host slower than the drive therefore makes the emulator late in answering —
// the reply still holds the averages over exactly the cycles between the two reads — and never produces
// the zero-cycle reply of a stalled control interrupt, which a real VESC cannot send.
//
// Status broadcasts go out at their drive times (the firmware's two status threads), carrying the state
// at those instants; the caller may also run the drive ahead while idle, up to a drive time that no poll
// still unread can precede (run_to()). A poll older than the drive time (a run_to() went past it before
// the poll was seen) is read at once and counted in `behind`; if no cycle then separates it from the
// previous read, one more cycle runs first (the reply thread of a firmware runs after its next control
// interrupt), so a single poller never meets an empty read.

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>

#include "rpem/can/vesc.hpp"
#include "rpem/sim/truth_log.hpp"
#include "rpem/sim/vesc_motor.hpp"

namespace rpem::sim {

/// One of the firmware's status threads (comm_can.c, cancom_status_thread/_2): the statuses whose bit is
/// set in `msgs` (bit k: status k+1), every 1/rate_Hz; rate 0: off.
struct VescStatusThread {
  double rate_Hz = 0.0;
  std::uint32_t msgs = 0;
};

class OnDemandVesc {
 public:
  struct Settings {
    VescMotor::Settings motor;
    std::array<VescStatusThread, 2> status{{{50.0, 0x19}, {5.0, 0x26}}};
    std::int64_t truth_period_ns = 10'000'000;  ///< a truth row this often in drive time (with a writer)
  };
  struct Read {
    can::vesc::Values values;  ///< every field (VescMotor::read_values)
    int cycles = 0;            ///< control cycles the averages cover
    bool behind = false;       ///< the drive had run past the poll's arrival before it was read
  };
  struct Counters {
    std::uint64_t reads = 0, behind = 0, empty_reads = 0, statuses = 0;  ///< statuses: emitted
  };

  /// `truth`, if given, receives the plant's true state every truth_period_ns of drive time.
  OnDemandVesc(Scenario scenario, const Settings& settings, TruthLogWriter* truth = nullptr);

  /// Runs the drive up to drive time `t_ns`, handing each status due on the way to `emit(Status)` at its
  /// own drive time (unless silent). False once the scenario has ended.
  template <class Emit>
  bool run_to(std::int64_t t_ns, Emit&& emit) {
    reached_ns_ = std::max(reached_ns_, t_ns);
    for (;;) {
      const std::size_t k = next_status_thread();
      const bool status_first = k < threads_.size() && next_status_ns_[k] <= t_ns;
      if (!advance(status_first ? next_status_ns_[k] : t_ns)) return false;
      if (!status_first) return true;
      for (int number = 1; number <= 6; ++number) {
        if (((threads_[k].msgs >> (number - 1)) & 1U) == 0) continue;
        if (silent_) continue;
        ++counters_.statuses;
        emit(motor_.status(number));
      }
      next_status_ns_[k] += status_period_ns_[k];
    }
  }

  /// A values request that arrived at drive time `t_ns`: runs the drive up to it, then reads and resets
  /// the averages. Nothing once the scenario has ended.
  template <class Emit>
  std::optional<Read> poll(std::int64_t t_ns, Emit&& emit) {
    const bool behind = t_ns < reached_ns_;
    if (!run_to(t_ns, emit)) return std::nullopt;
    if (behind && motor_.cycles_since_read() == 0 && !motor_.step()) return std::nullopt;
    return read(behind);
  }

  /// Silent: statuses are not emitted (the drive and its averages run on; the caller answers no poll).
  void set_silent(bool silent) noexcept { silent_ = silent; }
  [[nodiscard]] std::int64_t time_ns() const noexcept { return motor_.time_ns(); }
  [[nodiscard]] const Counters& counters() const noexcept { return counters_; }
  [[nodiscard]] const VescMotor& motor() const noexcept { return motor_; }

 private:
  bool advance(std::int64_t t_ns);
  [[nodiscard]] std::size_t next_status_thread() const noexcept;  ///< size(): none
  Read read(bool behind) noexcept;

  VescMotor motor_;
  std::array<VescStatusThread, 2> threads_;
  std::array<std::int64_t, 2> status_period_ns_{};
  std::array<std::int64_t, 2> next_status_ns_{};
  TruthLogWriter* truth_;
  std::int64_t truth_period_ns_;
  std::int64_t next_truth_ns_ = 0;
  std::int64_t reached_ns_ = 0;  ///< the latest drive time asked for
  bool silent_ = false;
  Counters counters_;
};

}  // namespace rpem::sim
