#pragma once
// rpemd's publisher thread, a PersistingPublisher: it publishes, and it persists. It turns the loop's
// reports into LCM messages (encoded into buffers allocated once; LCM's C++ publish(const T*) would
// allocate per call), assembles RPEM_DIAGNOSTICS from the rows the loop, the source and the control
// thread send it, persists the last good estimates in the state file, and prints the status line. It is
// the one consumer of three queues and owns the LCM publishing instance and the state file. A slow or
// failing network costs only this thread: the loop drops reports it cannot queue.

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rpem/auth/mac.hpp"
#include "rpem/daemon/daemon_config.hpp"
#include "rpem/daemon/latency_histogram.hpp"
#include "rpem/daemon/messages.hpp"
#include "rpem/daemon/source.hpp"
#include "rpem/daemon/spsc_queue.hpp"
#include "rpem/daemon/state_file.hpp"

namespace rpem::daemon {

/// The publisher's counters: it is their one writer.
struct PublisherCounters {
  std::int64_t publish_failures = 0;
  std::int64_t state_writes = 0;
  std::int64_t state_write_failures = 0;
};

/// How long the publisher thread sleeps when its queues are empty: half the period of its fastest publication,
///   idle = clamp(0.5 / max(estimate_rate_Hz, measurement_rate_Hz, diagnostics_rate_Hz), 1 ms, 20 ms),
/// 5 ms at the default rates (measurement 100 Hz). A report then waits at most half a publication period, and a
/// slowly publishing rpemd (several per host, docs/rpemd.md) wakes up less often.
[[nodiscard]] std::int64_t publisher_idle_ns(const LcmConfig& lcm) noexcept;

class PersistingPublisher {
 public:
  struct Queues {
    SpscQueue<Report>::Consumer loop;
    SpscQueue<SourceReport>::Consumer source;
    SpscQueue<ControlReport>::Consumer control;
  };
  struct Identity {
    std::string source_type;  ///< diagnostics_t.source
    std::string source_name;  ///< diagnostics_t.source_name
    StateFileStatus state_file_status = StateFileStatus::kNone;
    /// The state file's thermal state where the fusion resumed it: written again, with its own time, until the
    /// fusion reports its own (a restart while no sample arrives keeps it for the next).
    PersistedThermal resumed_thermal;
  };

  /// `config` is the fixed part: nothing the publisher uses changes on a reload.
  /// `publish_key`: signs RPEM_ESTIMATE and RPEM_DIAGNOSTICS (rpem/auth/mac.hpp); none: key id 0.
  PersistingPublisher(const FixedConfig& config, Identity identity, Queues queues,
                      std::optional<auth::Key> publish_key = std::nullopt);
  ~PersistingPublisher();

  /// The thread body; runs until `stop` is set and the loop's queue is drained, then writes the
  /// state file a last time.
  void run(const std::atomic<bool>& stop);

  /// CAN receive → LCM publish over the whole run (read after the thread has stopped).
  [[nodiscard]] const WideLatencyHistogram& rx_to_publish() const noexcept { return rx_to_publish_run_; }

 private:
  struct Lcm;
  void connect();
  void drain_reports();
  void publish_estimate(const EstimateReport& r);
  void publish_measurement(const MeasurementReport& r);
  void publish_diagnostics(const LoopStatsReport& r);
  void maybe_write_state(bool force);
  void print_status(const EstimateReport& r);
  /// Once: the note that the thermal fusion's soaked start went untested although a winding sensor is configured.
  void say_untested_start(const EstimateReport& r);
  template <class Message>
  void publish(const std::string& channel, Message& m);

  const FixedConfig config_;
  const Identity identity_;
  const std::optional<auth::Key> publish_key_;  ///< the one copy, in locked memory (rpem/auth/key.hpp)
  Queues queues_;
  PublisherCounters counters_;
  std::unique_ptr<Lcm> lcm_;
  std::int64_t next_connect_us_ = 0;
  std::vector<std::uint8_t> buffer_;
  const std::string estimate_channel_, measurement_channel_, diagnostics_channel_;
  std::string state_path_;

  SourceReport source_;                     ///< the newest from the source thread
  ControlReport control_;                   ///< the newest from the control thread
  WideLatencyHistogram rx_to_publish_;      ///< since the last diagnostics message
  WideLatencyHistogram rx_to_publish_run_;  ///< the whole run
  EstimateReport last_estimate_;
  bool have_estimate_ = false;
  bool said_untested_start_ = false;
  PersistedThermal thermal_;  ///< the fusion's newest state (or the resumed one), persisted
  std::int64_t next_state_write_s_ = 0;
  std::int64_t next_status_us_ = 0;
};

}  // namespace rpem::daemon
