#pragma once
// Where rpemd's samples come from, each on its own thread, into the loop's input queue:
//   CanSource — SocketCAN + the telemetry decoder (rpem::can)
//   SimSource — the built-in simulated drive (rpem::sim), paced in real time
// Counters are atomics the publisher reads for diagnostics.

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include "rpem/core/drive_sample.hpp"
#include "rpem/daemon/daemon_config.hpp"
#include "rpem/daemon/spsc_queue.hpp"

namespace rpem::daemon {

struct SourceStats {
  std::atomic<std::int64_t> samples{0};
  std::atomic<std::int64_t> queue_drops{0};  ///< input queue full
  // CAN decoder
  std::atomic<std::int64_t> frames{0}, unknown_id{0}, wrong_dlc{0}, bad_version{0}, crc_error{0}, frames_lost{0},
      duplicated{0}, reordered{0}, stale{0}, out_of_range{0}, invalid_value{0}, incomplete{0}, gaps{0};
  // CAN socket
  std::atomic<std::int64_t> kernel_drops{0}, reopens{0}, error_frames{0}, bus_off{0}, error_passive{0},
      controller_overflow{0};
  // Simulated drive: its true parameters, for the status line
  std::atomic<double> truth_psi_m_Wb{0.0}, truth_r_s_Ohm{0.0};
  std::atomic<bool> simulated{false};
};

class SampleSource {
 public:
  virtual ~SampleSource() = default;
  /// Starts the thread; it runs until `stop` is set.
  virtual void start(std::atomic<bool>& stop) = 0;
  virtual void join() = 0;
  [[nodiscard]] virtual std::string name() const = 0;
};

/// Builds the configured source. Throws std::runtime_error if it cannot start (e.g. a bad scenario).
[[nodiscard]] std::unique_ptr<SampleSource> make_source(const DaemonConfig& config, SpscQueue<core::DriveSample>& out,
                                                        SourceStats& stats);

}  // namespace rpem::daemon
