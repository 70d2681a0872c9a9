#pragma once
// rpemd as a whole (docs/rpemd.md, "Threads"): the Daemon owns the queues and the threads; its control
// thread (the caller of run()) owns the configuration.
//
//   source thread  ──samples──▶  loop thread  ──reports──▶  publisher thread ──▶ LCM, state file, status
//        └──────────────────source reports──────────────────────▲
//   control thread ──commands──▶ (loop)        control reports──┘
//
// Every queue is an SpscQueue with exactly one producer and one consumer.

#include <atomic>
#include <memory>
#include <string>
#include <thread>

#include "rpem/daemon/daemon_config.hpp"
#include "rpem/daemon/loop_thread.hpp"
#include "rpem/daemon/messages.hpp"
#include "rpem/daemon/publisher.hpp"
#include "rpem/daemon/source.hpp"
#include "rpem/daemon/spsc_queue.hpp"
#include "rpem/daemon/state_file.hpp"

namespace rpem::daemon {

/// What the command line says.
struct DaemonOptions {
  std::string config_path;     ///< empty: the built-in configuration (the simulated drive)
  std::string can_interface;   ///< non-empty: the CAN source on this interface, whatever the file says
  std::string histogram_path;  ///< at exit, the loop's wake-up latency histogram (cyclictest's format)
};

/// The configuration as rpemd runs it: the file or the built-in one, with the command line's
/// overrides. Throws io::InputError. Also what a reload reads.
[[nodiscard]] DaemonConfig load_configuration(const DaemonOptions& options);

class Daemon {
 public:
  /// Builds the source (throws io::InputError if it cannot be, e.g. a bad scenario). Starts nothing.
  Daemon(DaemonOptions options, DaemonConfig config);
  ~Daemon();
  Daemon(const Daemon&) = delete;
  Daemon& operator=(const Daemon&) = delete;

  /// Starts the threads, runs the control thread on the caller until SIGTERM or SIGINT, stops the
  /// threads in order (source and loop, then the publisher after it has drained its queue and written
  /// the state file). Returns the exit code (io/exit_codes.hpp).
  int run();

 private:
  void seed_from_state_file();
  /// On stderr, where the fusion starts soaked with nothing to test it (docs/thermal.md).
  void say_untested_soak() const;
  /// The thermal fusion starts from the file's state where it is of the configured network (or says why not).
  void resume_thermal(const PersistedThermal& saved, std::int64_t now_s);
  void start_threads();
  void stop_threads();
  void print_summary() const;

  DaemonOptions options_;
  DaemonConfig config_;  ///< until run() hands it to the control thread
  // Each queue's ends, until run() hands them to the threads' owners (the source's here, below).
  SpscQueue<SourceSample>::Ends samples_ = SpscQueue<SourceSample>::make(8192);
  SpscQueue<SourceReport>::Ends source_reports_ = SpscQueue<SourceReport>::make(8);
  SpscQueue<Command>::Ends commands_ = SpscQueue<Command>::make(16);
  SpscQueue<ControlReport>::Ends control_reports_ = SpscQueue<ControlReport>::make(8);
  SpscQueue<Report>::Ends reports_ = SpscQueue<Report>::make(4096);
  std::unique_ptr<SampleSource> source_;
  std::string source_name_;
  StateFileStatus state_file_status_ = StateFileStatus::kNone;
  PersistedThermal resumed_thermal_;  ///< the state file's thermal state where the fusion resumed it
  std::unique_ptr<LoopThread> loop_;
  std::unique_ptr<PersistingPublisher> publisher_;
  SourceOutput source_output_{std::move(samples_.producer), std::move(source_reports_.producer)};
  std::atomic<bool> stop_acquisition_{false}, stop_publisher_{false};
  std::thread source_thread_, loop_thread_, publisher_thread_;
};

}  // namespace rpem::daemon
