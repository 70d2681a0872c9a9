#pragma once
// rpemd's publisher thread: turns the loop's reports into LCM messages (encoded into buffers allocated
// once; LCM's C++ publish(const T*) would allocate per call), receives RPEM_COMMAND messages and hands
// the accepted ones to the loop, persists the last converged estimates, and prints the status line.
// A slow or failing network costs only this thread: the loop drops reports it cannot queue.

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "rpem/daemon/daemon_config.hpp"
#include "rpem/daemon/latency_histogram.hpp"
#include "rpem/daemon/messages.hpp"
#include "rpem/daemon/sources.hpp"
#include "rpem/daemon/spsc_queue.hpp"
#include "rpem/daemon/state_file.hpp"

namespace rpem::daemon {

struct PublisherCounters {
  std::atomic<std::int64_t> publish_failures{0};
  std::atomic<std::int64_t> commands_received{0};
  std::atomic<std::int64_t> commands_malformed{0};
  std::atomic<std::int64_t> commands_rejected{0};
  std::atomic<std::int64_t> state_writes{0};
  std::atomic<std::int64_t> state_write_failures{0};
  std::atomic<std::int64_t> config_reload_failures{0};
};

class Publisher {
 public:
  Publisher(const DaemonConfig& config, std::string source_name, SpscQueue<Report>& reports,
            SpscQueue<Command>& commands, const SourceStats& source_stats, StateFileStatus state_file_status);
  ~Publisher();

  /// The thread body; runs until `stop` is set and the report queue is drained, then writes the
  /// state file a last time.
  void run(std::atomic<bool>& stop);

  [[nodiscard]] PublisherCounters& counters() noexcept { return counters_; }
  /// CAN receive → LCM publish over the whole run (read after the thread has stopped).
  [[nodiscard]] const LatencyHistogram& rx_to_publish() const noexcept { return rx_to_publish_run_; }
  [[nodiscard]] std::string channel(const char* name) const { return config_.channel_prefix + name; }

 private:
  struct Lcm;
  void publish_estimate(const EstimateReport& r);
  void publish_measurement(const MeasurementReport& r);
  void publish_diagnostics(const LoopStatsReport& r);
  void handle_command(const void* data, std::uint32_t size);
  void maybe_write_state(bool force);
  void print_status(const EstimateReport& r);
  bool publish_raw(const std::string& channel, std::int64_t size);

  DaemonConfig config_;
  std::string source_name_;
  SpscQueue<Report>& reports_;
  SpscQueue<Command>& commands_;
  const SourceStats& source_;
  StateFileStatus state_file_status_;
  PublisherCounters counters_;
  std::unique_ptr<Lcm> lcm_;
  std::vector<std::uint8_t> buffer_;
  std::string state_path_;

  LatencyHistogram rx_to_publish_;      ///< since the last diagnostics message
  LatencyHistogram rx_to_publish_run_;  ///< the whole run
  EstimateReport last_estimate_;
  bool have_estimate_ = false;
  std::int64_t last_seq_accepted_ = 0;
  CommandResult last_reject_ = CommandResult::kNone;
  std::int64_t last_reject_seq_ = 0;
  std::int64_t next_state_write_s_ = 0;
  std::int64_t next_status_us_ = 0;
  bool state_dirty_ = false;
  double written_psi_ = 0.0, written_rs_ = 0.0;
};

}  // namespace rpem::daemon
